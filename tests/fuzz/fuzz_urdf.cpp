// libFuzzer harness: a robot's URDF, imported and compiled as `metriplex run robot.urdf` does.
#include "engine/core/input_error.hpp"
#include "fuzz_input.hpp"
#include "models/scene/scene_loader.hpp"

#include <cstddef>
#include <cstdint>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    mpx::loadScene(mpx::fuzz::writeInput(data, size, ".urdf"));
  } catch (const mpx::InputError&) {
  }
  return 0;
}
