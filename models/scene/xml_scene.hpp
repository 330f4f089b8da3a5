#pragma once
// The XML front end (docs/scene-format.md): a <metriplex> document read once into a
// SceneSpec. Settings elements (<simulation>, <solver>, <gravity>, <constraints>) fill the
// spec's settings, <urdf> elements are replaced by their robot's elements, every other
// element is kept as it is, with its file and line, for the compiler.
#include "models/scene/scene_spec.hpp"

#include <string>

namespace mpx {

// `label` names the document in messages and is where relative paths (meshes, URDFs) start.
// Throws InputError (file, line, what is wrong).
SceneSpec readXmlScene(const std::string& text, const std::string& label);

}  // namespace mpx
