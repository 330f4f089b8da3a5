#pragma once
// The two ways a URDF enters a scene (docs/scene-format.md, "URDF robots"): as a scene of its
// own (`metriplex run robot.urdf`) and as <urdf> elements of an XML scene (xml_scene.cpp).
// Both append plain scene elements to a SceneSpec, so the compiler never sees a URDF.
#include "models/scene/scene_spec.hpp"
#include "models/scene/urdf_import.hpp"

#include <string>

namespace mpx {

// A scene holding the URDF at `path` with the defaults: fixed root at the origin, joints at 0
// and at rest, dt 1e-3 s, t_end 2 s, gravity 0 0 -9.81; `options` as a <urdf> element's
// (the command line's --urdf-limits sets `limits`).
SceneSpec readUrdfScene(const std::string& path, const UrdfImportOptions& options = {});

}  // namespace mpx
