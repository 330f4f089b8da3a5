#include "models/scene/xml_scene.hpp"

#include "engine/stepping/method.hpp"
#include "models/scene/element_reader.hpp"
#include "models/scene/urdf_import.hpp"

#include "models/scene/strict_xml.hpp"

#include <fmt/format.h>
#include <tinyxml2.h>

#include <filesystem>
#include <map>

namespace mpx {

namespace {

using tinyxml2::XMLElement;

ElementSpec toSpec(const XMLElement& element, const std::string& label, int index) {
  ElementSpec spec;
  spec.tag = element.Name();
  spec.where = {label, element.GetLineNum(), index};
  for (const tinyxml2::XMLAttribute* a = element.FirstAttribute(); a; a = a->Next())
    spec.attributes.emplace_back(a->Name(), a->Value());
  return spec;
}

void readSimulation(ElementReader& in, SceneSettings& settings) {
  settings.dt = in.positive("dt");
  settings.tEnd = in.positive("t_end");
  checkStepCount(settings.tEnd, settings.dt, in.where() + ": <simulation>");
  settings.integrator = in.text("integrator", "eem");
  const std::optional<Method> method = methodByName(settings.integrator);
  if (!method) in.fail("unknown integrator '" + settings.integrator + "' (choose " + kMethodNames + ")");
  const std::string variable = in.text("thermal_variable", "temperature");
  if (variable != "temperature" && variable != "entropy")
    in.fail("thermal_variable must be 'temperature' or 'entropy', got '" + variable + "'");
  settings.thermalVariable = variable == "entropy" ? ThermalVariable::Entropy : ThermalVariable::Temperature;
  // an integrator that fixes the thermal variable decides it, unless the scene says otherwise
  if (method->thermalVariable) {
    if (in.has("thermal_variable") && *method->thermalVariable != settings.thermalVariable)
      in.fail("integrator '" + settings.integrator + "' contradicts thermal_variable='" + variable + "'");
    settings.thermalVariable = *method->thermalVariable;
  }
  const std::string form = in.text("discrete_gradient", "partitioned");
  if (form != "partitioned" && form != "gonzalez")
    in.fail("discrete_gradient must be 'partitioned' or 'gonzalez', got '" + form + "'");
  settings.discreteGradient = form == "gonzalez" ? DiscreteGradientForm::Gonzalez : DiscreteGradientForm::Partitioned;
  settings.adaptive = in.flag("adaptive", false);
  if (method->adaptive && in.has("adaptive") && !settings.adaptive)
    in.fail("integrator '" + settings.integrator + "' contradicts adaptive=\"false\"");
  settings.relativeTolerance = in.positive("rtol", settings.relativeTolerance);
  if (settings.relativeTolerance < kSmallestRelativeTolerance)
    in.fail(fmt::format("rtol must be at least {:g} (below, round-off exceeds it)", kSmallestRelativeTolerance));
  settings.absoluteTolerance = in.has("atol") ? in.positive("atol") : 0.0;
}

void readSolver(ElementReader& in, NewtonSettings& n) {
  n.incrementTolerance = in.positive("increment_tolerance", n.incrementTolerance);
  n.residualTolerance = in.positive("residual_tolerance", n.residualTolerance);
  // more halvings than 50 take the step below 1e-15 of itself
  n.maxIterations = in.count("max_iterations", n.maxIterations, 1, 10000);
  n.maxCutbacks = in.count("max_cutbacks", n.maxCutbacks, 0, 50);
  n.predictor = in.flag("predictor", n.predictor);
  n.reuseContraction = in.nonNegative("reuse_contraction", n.reuseContraction);
  n.reuseBelowIncrement = in.nonNegative("reuse_below_increment", n.reuseBelowIncrement);
  n.symmetricFactorisation = in.flag("symmetric_factorisation", n.symmetricFactorisation);
  n.corotate = in.flag("corotate", n.corotate);
  if (!(n.reuseContraction < 1.0)) in.fail("reuse_contraction must be below 1 (0: full Newton)");
  if (n.symmetricFactorisation && n.reuseContraction == 0.0)
    in.fail("symmetric_factorisation approximates the tangent: it needs simplified Newton (reuse_contraction > 0)");
}

ConstraintSettings readConstraints(ElementReader& in) {
  const std::string enforcement = in.text("enforcement", "augmented_lagrangian");
  if (enforcement != "penalty" && enforcement != "augmented_lagrangian")
    in.fail("enforcement must be 'penalty' or 'augmented_lagrangian', got '" + enforcement + "'");
  ConstraintSettings settings;
  settings.enforcement = enforcement == "penalty" ? Enforcement::Penalty : Enforcement::AugmentedLagrangian;
  settings.stiffness = in.positive("stiffness", settings.stiffness);
  return settings;
}

// The attributes and <initial> children of one <urdf> element.
UrdfImportOptions readUrdfOptions(ElementReader& in, const XMLElement& include) {
  UrdfImportOptions options;
  options.floating = in.flag("floating", false);
  options.position = in.vector("position", Vec3::Zero());
  options.orientation = in.orientation("orientation");
  options.prefix = in.text("prefix", "");
  options.balanceInertia = in.flag("balance_inertia", false);
  options.limits = in.flag("limits", false);
  if (options.limits) {
    options.limitStiffness = in.positive("limit_stiffness", options.limitStiffness);
    options.limitDamping = in.nonNegative("limit_damping", 0.5 * options.limitStiffness);
  }
  for (const XMLElement* child = include.FirstChildElement(); child; child = child->NextSiblingElement()) {
    const ElementSpec spec = toSpec(*child, in.element().where.file, 0);
    ElementReader initial(spec);
    if (spec.tag != "initial") initial.fail("a <urdf> element holds <initial> elements only");
    const std::string joint = initial.text("joint");
    const UrdfJointState state{initial.number("position", 0.0), initial.number("velocity", 0.0)};
    if (!options.initial.emplace(joint, state).second)
      initial.fail("joint '" + joint + "' has an initial state already");
    initial.finish();
  }
  return options;
}

class XmlSceneReader {
 public:
  XmlSceneReader(const XMLElement& root, const std::string& label) : root_(root) {
    scene_.label = label;
    // every name a hand-written element declares, so that a URDF's generated name that
    // clashes is reported at the <urdf> rather than at a generated element
    for (const XMLElement* e = root.FirstChildElement(); e; e = e->NextSiblingElement())
      if (const char* name = e->Attribute("name")) declared_.emplace(name, e->GetLineNum());
  }

  SceneSpec read() {
    const ElementSpec rootSpec = toSpec(root_, scene_.label, 0);
    ElementReader root(rootSpec);
    if (rootSpec.tag != "metriplex")
      throw InputError(scene_.label, rootSpec.where.line,
                       "the root element must be <metriplex>, found <" + rootSpec.tag + ">");
    scene_.line = rootSpec.where.line;
    scene_.name = root.text("name", "scene");
    root.finish();
    // each settings element at most once (a second would silently override the first)
    std::map<std::string, int> settingsLines;
    for (const XMLElement* e = root_.FirstChildElement(); e; e = e->NextSiblingElement()) {
      const ElementSpec spec = toSpec(*e, scene_.label, static_cast<int>(scene_.elements.size()) + 1);
      ElementReader in(spec);
      if (spec.tag == "urdf") {
        expandUrdf(in, *e);
        continue;
      }
      if (e->FirstChildElement()) in.fail("<" + spec.tag + "> takes no child elements");
      const bool settings =
          spec.tag == "simulation" || spec.tag == "solver" || spec.tag == "gravity" || spec.tag == "constraints";
      if (settings && !settingsLines.emplace(spec.tag, spec.where.line).second)
        in.fail("a scene has at most one <" + spec.tag + "> element; the first is on line " +
                std::to_string(settingsLines[spec.tag]));
      if (spec.tag == "simulation") {
        readSimulation(in, scene_.settings);
      } else if (spec.tag == "solver") {
        readSolver(in, scene_.settings.newton);
      } else if (spec.tag == "gravity") {
        scene_.gravity = in.vector("g", Vec3::Zero());
      } else if (spec.tag == "constraints") {
        scene_.constraints = readConstraints(in);
      } else {
        scene_.elements.push_back(spec);
        continue;
      }
      in.finish();
    }
    if (!settingsLines.count("simulation"))
      throw InputError(scene_.label, root_.GetLineNum(), "<metriplex>: missing <simulation dt=... t_end=...> element");
    return std::move(scene_);
  }

 private:
  // Replace a <urdf> by its robot's elements.
  void expandUrdf(ElementReader& in, const XMLElement& include) {
    const std::filesystem::path file = in.text("file");
    const UrdfImportOptions options = readUrdfOptions(in, include);
    in.finish();
    const std::filesystem::path path =
        file.is_absolute() ? file : std::filesystem::path(scene_.label).parent_path() / file;
    const std::size_t first = scene_.elements.size();
    try {
      appendUrdfElements(path.string(), options, scene_);
    } catch (const InputError& e) {
      in.fail(e.what());
    }
    for (std::size_t k = first; k < scene_.elements.size(); ++k) {
      const std::string& name = *scene_.elements[k].find("name");
      const auto [it, inserted] = declared_.emplace(name, in.element().where.line);
      if (!inserted)
        in.fail("the URDF's element '" + name + "' clashes with the name used on line " + std::to_string(it->second) +
                " (a prefix=\"...\" attribute renames the URDF's elements)");
    }
  }

  const XMLElement& root_;
  SceneSpec scene_;
  std::map<std::string, int> declared_;
};

}  // namespace

SceneSpec readXmlScene(const std::string& text, const std::string& label) {
  tinyxml2::XMLDocument document;
  return XmlSceneReader(parseStrictXml(document, text, label, TextContent::Refused), label).read();
}

}  // namespace mpx
