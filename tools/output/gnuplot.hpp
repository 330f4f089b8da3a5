#pragma once
// The one way output writers run gnuplot (Debian package gnuplot-nox, installed by
// tools/install-deps.sh): a script file, its messages kept in a log.
#include <filesystem>
#include <string>

namespace mpx {

// Text as a double-quoted gnuplot string: quotes and backslashes escaped, control characters
// (a newline would start a new command) and backquotes (command substitution) as octal escapes.
std::string gnuplotQuoted(const std::string& text);

// Run gnuplot on `script`, its stderr into `log`. Throws std::runtime_error with the log's
// text if gnuplot fails.
void runGnuplot(const std::filesystem::path& script, const std::filesystem::path& log);

}  // namespace mpx
