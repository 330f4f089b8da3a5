// libFuzzer harness: a scene document, read and compiled as `metriplex run` does before it steps.
#include "engine/core/input_error.hpp"
#include "models/scene/scene_loader.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    mpx::loadSceneText(std::string(reinterpret_cast<const char*>(data), size), "fuzz.xml");
  } catch (const mpx::InputError&) {
  }
  return 0;
}
