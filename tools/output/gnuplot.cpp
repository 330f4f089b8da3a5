#include "tools/output/gnuplot.hpp"

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
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("''") : std::string(1, c);
  return quoted + "'";
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
