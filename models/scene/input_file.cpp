#include "models/scene/input_file.hpp"

#include "engine/core/input_error.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

namespace mpx {

std::string readInputFile(const std::string& path, const char* what) {
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  // a missing file is an error here too (ENOENT), said in the system's words
  if (error || !std::filesystem::exists(status))
    throw InputError(path + ": cannot open the " + what + " (" + (error ? error.message() : "no such file") + ")");
  if (!std::filesystem::is_regular_file(status))
    throw InputError(path + ": the " + what + " is not a regular file (a directory, device or pipe)");
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path + ": cannot open the " + what);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

}  // namespace mpx
