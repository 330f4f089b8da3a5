#include "models/scene/urdf_scene.hpp"

#include "models/scene/element_reader.hpp"
#include "models/scene/urdf_import.hpp"

#include <filesystem>
#include <map>

namespace mpx {

namespace {

using tinyxml2::XMLElement;

// Run defaults of a scene made of a URDF alone.
constexpr double kUrdfSceneStep = 1e-3;
constexpr double kUrdfSceneEndTime = 2.0;
constexpr const char* kUrdfSceneGravity = "0 0 -9.81";

// The attributes and <initial> children of one <urdf> element.
UrdfImportOptions readOptions(ElementReader& in, const XMLElement& include) {
  UrdfImportOptions options;
  options.floating = in.flag("floating", false);
  options.position = in.vector("position", Vec3::Zero());
  options.orientation = in.orientation("orientation");
  options.prefix = in.text("prefix", "");
  for (const XMLElement* child = include.FirstChildElement(); child; child = child->NextSiblingElement()) {
    ElementReader initial(*child, in.file());
    if (std::string(child->Name()) != "initial") initial.fail("a <urdf> element holds <initial> elements only");
    const std::string joint = initial.text("joint");
    const UrdfJointState state{initial.number("position", 0.0), initial.number("velocity", 0.0)};
    if (!options.initial.emplace(joint, state).second)
      initial.fail("joint '" + joint + "' has an initial state already");
    initial.finish();
  }
  return options;
}

// Expand one <urdf> in place. `declared` maps every name in the scene to its line, so a
// generated name that clashes is reported at the <urdf> rather than at a generated element.
void expand(XMLElement& include, const std::string& sceneFile, std::map<std::string, int>& declared) {
  ElementReader in(include, sceneFile);
  const std::filesystem::path file = in.text("file");
  const UrdfImportOptions options = readOptions(in, include);
  in.finish();
  const std::filesystem::path path = file.is_absolute() ? file : std::filesystem::path(sceneFile).parent_path() / file;
  const XMLElement* next = include.NextSiblingElement();
  try {
    insertUrdfElements(path.string(), options, include);
  } catch (const InputError& e) {
    in.fail(e.what());
  }
  for (const XMLElement* e = include.NextSiblingElement(); e != next; e = e->NextSiblingElement()) {
    const std::string name = e->Attribute("name");
    const auto [it, inserted] = declared.emplace(name, in.line());
    if (!inserted)
      in.fail("the URDF's element '" + name + "' clashes with the name used on line " + std::to_string(it->second) +
              " (a prefix=\"...\" attribute renames the URDF's elements)");
  }
}

}  // namespace

void writeUrdfScene(tinyxml2::XMLDocument& document, const std::string& path) {
  XMLElement* root = document.NewElement("metriplex");
  root->SetAttribute("name", std::filesystem::path(path).stem().string().c_str());
  document.InsertEndChild(root);
  XMLElement* simulation = root->InsertNewChildElement("simulation");
  simulation->SetAttribute("dt", kUrdfSceneStep);
  simulation->SetAttribute("t_end", kUrdfSceneEndTime);
  XMLElement* gravity = root->InsertNewChildElement("gravity");
  gravity->SetAttribute("g", kUrdfSceneGravity);
  insertUrdfElements(path, UrdfImportOptions{}, *gravity);
}

void expandUrdfIncludes(tinyxml2::XMLDocument& scene, const std::string& sceneFile) {
  XMLElement* root = scene.RootElement();
  if (!root) return;
  std::map<std::string, int> declared;
  for (const XMLElement* e = root->FirstChildElement(); e; e = e->NextSiblingElement())
    if (const char* name = e->Attribute("name")) declared.emplace(name, e->GetLineNum());
  for (XMLElement* e = root->FirstChildElement(); e;) {
    XMLElement* next = e->NextSiblingElement();
    if (std::string(e->Name()) == "urdf") {
      expand(*e, sceneFile, declared);
      root->DeleteChild(e);
    }
    e = next;
  }
}

}  // namespace mpx
