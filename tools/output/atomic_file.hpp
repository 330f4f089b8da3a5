#pragma once
// Output files that exist whole or not at all: written to path + ".part" and renamed over path
// once complete, so a crash or a full disk never leaves a file that looks finished.
#include <functional>
#include <ostream>
#include <string>

namespace mpx {

// Write `path` through write(stream), with round-trip precision for doubles. Throws
// std::runtime_error naming the path if it cannot be written (the .part file is removed).
void writeAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace mpx
