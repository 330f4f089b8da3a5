#pragma once
// What the fuzz harnesses share: the front ends that read files get the fuzzer's bytes through
// one file per process, rewritten for every input, and an InputError is the expected answer to
// malformed input (anything else escaping, a crash or a sanitizer report is a finding).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>

namespace mpx::fuzz {

// A file in the temporary directory holding `size` bytes of `data`; `extension` as the front
// end expects it (".urdf", ".msh").
inline const std::string& writeInput(const std::uint8_t* data, std::size_t size, const char* extension) {
  static const std::string path = "/tmp/metriplex-fuzz-" + std::to_string(getpid()) + extension;
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), size);
  return path;
}

}  // namespace mpx::fuzz
