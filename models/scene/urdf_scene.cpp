#include "models/scene/urdf_scene.hpp"

#include "models/scene/urdf_import.hpp"

#include <filesystem>

namespace mpx {

namespace {

// Run defaults of a scene made of a URDF alone.
constexpr double kUrdfSceneStep = 1e-3;
constexpr double kUrdfSceneEndTime = 2.0;
const Vec3 kUrdfSceneGravity(0.0, 0.0, -9.81);

}  // namespace

SceneSpec readUrdfScene(const std::string& path, const UrdfImportOptions& options) {
  SceneSpec scene;
  scene.name = std::filesystem::path(path).stem().string();
  scene.label = path;
  scene.settings.dt = kUrdfSceneStep;
  scene.settings.tEnd = kUrdfSceneEndTime;
  scene.gravity = kUrdfSceneGravity;
  appendUrdfElements(path, options, scene);
  return scene;
}

}  // namespace mpx
