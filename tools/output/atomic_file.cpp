#include "tools/output/atomic_file.hpp"

#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>

namespace mpx {

void writeAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  const std::string part = path + ".part";
  std::ofstream out(part);
  out.precision(std::numeric_limits<double>::max_digits10);
  if (out) write(out);
  out.close();
  std::error_code error;
  if (out) std::filesystem::rename(part, path, error);
  if (!out || error) {
    std::filesystem::remove(part, error);
    throw std::runtime_error("cannot write " + path);
  }
}

}  // namespace mpx
