#include "tools/output/gnuplot.hpp"

#include <fmt/format.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace mpx {

namespace {

// Single-quoted for the shell: a quote inside becomes '\''.
std::string shellQuoted(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

}  // namespace

std::string gnuplotQuoted(const std::string& text) {
  // a newline would end the command inside the string and start another (gnuplot runs a line
  // that starts with '!' in the shell), and gnuplot runs `...` in the shell even inside double
  // quotes; in double quotes it reads octal escapes instead of both
  std::string quoted = "\"";
  for (char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\')
      quoted += std::string("\\") + c;
    else if (byte < 0x20 || byte == 0x7f || c == '`')
      quoted += fmt::format("\\{:03o}", byte);
    else
      quoted += c;
  }
  return quoted + "\"";
}

void runGnuplot(const std::filesystem::path& script, const std::filesystem::path& log) {
  const std::string command = "gnuplot " + shellQuoted(script.string()) + " 2> " + shellQuoted(log.string());
  if (std::system(command.c_str()) == 0) return;
  std::ifstream messages(log);
  std::stringstream text;
  text << messages.rdbuf();
  throw std::runtime_error("gnuplot failed on " + script.string() + ": " + text.str());
}

}  // namespace mpx
