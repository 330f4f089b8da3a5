#pragma once
// The two ways a URDF enters a scene (docs/scene-format.md, "URDF robots"): as a scene of its
// own (`metriplex run robot.urdf`) and as <urdf> elements of an XML scene. Both produce plain
// scene elements before the compiler counts dofs, so it never sees a URDF.
#include <tinyxml2.h>

#include <string>

namespace mpx {

// Fill an empty document with a scene holding the URDF at `path` with the defaults: fixed
// root at the origin, joints at 0 and at rest, dt 1e-3 s, t_end 2 s, gravity 0 0 -9.81.
void writeUrdfScene(tinyxml2::XMLDocument& document, const std::string& path);

// Replace every <urdf> child of the root by the elements of its robot. `sceneFile` is where
// the scene came from: URDF paths are relative to its directory and messages name it.
void expandUrdfIncludes(tinyxml2::XMLDocument& scene, const std::string& sceneFile);

}  // namespace mpx
