// libFuzzer harness: a Gmsh mesh file, read as a scene's <solid mesh="..."> reads it.
#include "engine/core/input_error.hpp"
#include "fuzz_input.hpp"
#include "models/scene/gmsh_reader.hpp"

#include <cstddef>
#include <cstdint>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    mpx::readGmshMesh(mpx::fuzz::writeInput(data, size, ".msh"));
  } catch (const mpx::InputError&) {
  }
  return 0;
}
