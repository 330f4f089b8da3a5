#pragma once
// Invalid input: a scene file, a URDF or a command-line option. The message names the file,
// the line and what is wrong; the command-line tool turns it into exit code 2.
#include <stdexcept>
#include <string>

namespace mpx {

// Text of an input file as a message quotes it: bytes outside printable ASCII as \xHH, so that a
// message stays one line of plain text (a binary file's bytes would garble the terminal).
inline std::string printable(const std::string& text) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    out += byte >= 0x20 && byte < 0x7f ? std::string(1, c) : std::string("\\x") + digits[byte >> 4] + digits[byte & 15];
  }
  return out;
}

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
  InputError(const std::string& file, int line, const std::string& message)
      : std::runtime_error(file + ":" + std::to_string(line) + ": " + message) {}
};

}  // namespace mpx
