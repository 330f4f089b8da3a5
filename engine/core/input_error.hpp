#pragma once
// Invalid input: a scene file, a URDF or a command-line option. The message names the file,
// the line and what is wrong; the command-line tool turns it into exit code 2.
#include <stdexcept>
#include <string>

namespace mpx {

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
  InputError(const std::string& file, int line, const std::string& message)
      : std::runtime_error(file + ":" + std::to_string(line) + ": " + message) {}
};

}  // namespace mpx
