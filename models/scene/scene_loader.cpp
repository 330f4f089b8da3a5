#include "models/scene/scene_loader.hpp"

#include "models/scene/scene_compiler.hpp"
#include "models/scene/urdf_scene.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace mpx {

namespace {

CompiledScene compileDocument(tinyxml2::XMLDocument& document, const std::string& label,
                              std::optional<ThermalVariable> thermalVariable) {
  if (document.Error())
    throw InputError(label, document.ErrorLineNum(), std::string("malformed XML: ") + document.ErrorStr());
  const XMLElement* root = document.RootElement();
  if (!root) throw InputError(label, 1, "the file holds no XML element");
  expandUrdfIncludes(document, label);
  return SceneCompiler(*root, label, thermalVariable).compile();
}

}  // namespace

CompiledScene loadScene(const std::string& path, std::optional<ThermalVariable> thermalVariable) {
  // a URDF alone is a scene with default settings
  if (std::filesystem::path(path).extension() == ".urdf") {
    tinyxml2::XMLDocument document;
    writeUrdfScene(document, path);
    return compileDocument(document, path, thermalVariable);
  }
  std::ifstream file(path);
  if (!file) throw InputError(path + ": cannot open the scene file");
  std::stringstream text;
  text << file.rdbuf();
  return loadSceneText(text.str(), path, thermalVariable);
}

CompiledScene loadSceneText(const std::string& text, const std::string& label,
                            std::optional<ThermalVariable> thermalVariable) {
  tinyxml2::XMLDocument document;
  document.Parse(text.c_str(), text.size());
  return compileDocument(document, label, thermalVariable);
}

}  // namespace mpx