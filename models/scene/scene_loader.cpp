#include "models/scene/scene_loader.hpp"

#include "engine/stepping/method.hpp"

#include "models/scene/input_file.hpp"
#include "models/scene/urdf_scene.hpp"
#include "models/scene/xml_scene.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

namespace mpx {

namespace {

// Position scale of a scene without any length (e.g. only thermal nodes).
constexpr double kDefaultLength = 1.0;

// What the XML reader checks on <simulation>, <solver>, <gravity> and <constraints>, for
// scenes built in code.
void checkSettings(const SceneSpec& scene) {
  const SceneSettings& s = scene.settings;
  const NewtonSettings& n = s.newton;
  auto require = [&](bool holds, const std::string& what) {
    if (!holds) throw InputError(scene.label + ": " + what);
  };
  require(s.dt > 0.0 && std::isfinite(s.dt) && s.tEnd > 0.0 && std::isfinite(s.tEnd),
          "the simulation needs finite dt > 0 and t_end > 0");
  require(methodByName(s.integrator).has_value(), "unknown integrator '" + s.integrator + "'");
  checkStepCount(s.tEnd, s.dt, SourceLocation{scene.label, scene.line, 0}.describe() + ": <simulation>");
  require(s.relativeTolerance >= kSmallestRelativeTolerance && std::isfinite(s.relativeTolerance) &&
              s.absoluteTolerance >= 0.0 && std::isfinite(s.absoluteTolerance),
          "rtol must be at least 1e-14 and atol non-negative");
  require(n.incrementTolerance > 0.0 && n.residualTolerance > 0.0, "Newton tolerances must be positive");
  require(n.maxIterations >= 1 && n.maxCutbacks >= 0, "max_iterations must be at least 1, max_cutbacks at least 0");
  require(n.reuseContraction >= 0.0 && n.reuseContraction < 1.0, "reuse_contraction must be in [0, 1)");
  require(!n.symmetricFactorisation || n.reuseContraction > 0.0,
          "symmetric_factorisation approximates the tangent: it needs simplified Newton (reuse_contraction > 0)");
  require(n.reuseBelowIncrement >= 0.0 && std::isfinite(n.reuseBelowIncrement),
          "reuse_below_increment must be finite and non-negative");
  require(scene.gravity.allFinite(), "gravity must be finite");
  require(scene.constraints.stiffness > 0.0 && std::isfinite(scene.constraints.stiffness),
          "the constraint stiffness must be positive");
  if (const std::string problem = fileNameProblem(scene.name); !problem.empty())
    throw InputError(SourceLocation{scene.label, scene.line, 0}.describe() + ": scene name " + problem);
}

// The state layout: each element's declared dofs, in element order within each block.
Layout layoutOf(const std::vector<DofDemand>& demands, std::vector<DofDemand>& firsts) {
  DofDemand total;
  for (const DofDemand& d : demands) {
    firsts.push_back(total);
    total.positions += d.positions;
    total.thermal += d.thermal;
    total.internal += d.internal;
    total.multipliers += d.multipliers;
  }
  return Layout({total.positions, total.positions, total.thermal, total.internal, total.multipliers});
}

// Newton's increment scales: a length for positions, length per run time for velocities.
void setMechanicalScales(SceneBuild& build, double tEnd) {
  const double length = build.positionScale > 0.0 ? build.positionScale : kDefaultLength;
  for (int i = 0; i < build.layout.size(Block::Position); ++i) {
    const int p = build.layout.dof(Block::Position, i), v = build.layout.dof(Block::Velocity, i);
    build.scale[p] = std::max(build.scale[p], length);
    build.scale[v] = std::max(std::abs(build.state[v]), length / tEnd);
  }
}

// The initial state must give finite measures (those the history writes) and positive
// temperatures: a value that overflows (a mass of 1e308 moving at 1e308) or an entropy beyond
// what a capacity's temperature can represent would otherwise only fail in the first step.
// Names the element whose measure fails.
void checkInitialState(const Model& model, const SceneSpec& scene,
                       const std::map<const Component*, std::size_t>& elementIndex) {
  for (const auto& component : model.components()) {
    Measures own;
    own.nodeTemperature.assign(model.thermalNodeNames().size(), 1.0);
    component->measure(model.initialState().data(), own);
    const bool temperaturesPositive =
        std::all_of(own.nodeTemperature.begin(), own.nodeTemperature.end(), [](double t) { return t > 0.0; });
    if (finite(own) && temperaturesPositive) continue;
    ElementReader(scene.elements[elementIndex.at(component.get())])
        .fail(fmt::format("the initial state gives a measure that is not finite or a temperature that is not "
                          "positive (energy {:.3g}, entropy {:.3g})",
                          own.energy, own.entropy));
  }
}

}  // namespace

CompiledScene compileScene(const SceneSpec& scene, std::optional<ThermalVariable> thermalVariable) {
  checkSettings(scene);
  SceneBuild build(scene, thermalVariable.value_or(scene.settings.thermalVariable));

  // pass 1: what every element needs from the state
  std::vector<const ElementKind*> kinds;
  std::vector<DofDemand> demands;
  for (const ElementSpec& element : scene.elements) {
    ElementReader in(element);
    const ElementKind* kind = findElementKind(element.tag);
    if (!kind) in.fail("unknown element (the elements a scene may hold: " + elementTags() + ")");
    kinds.push_back(kind);
    demands.push_back(kind->declare ? kind->declare(in, build) : DofDemand{});
  }
  std::vector<DofDemand> firsts;
  build.allocate(layoutOf(demands, firsts));

  // pass 2: every element builds from the dofs it declared, and takes all of them
  std::map<const Component*, std::size_t> elementIndex;
  for (std::size_t k = 0; k < scene.elements.size(); ++k) {
    ElementReader in(scene.elements[k]);
    DofRange dofs(build.layout, firsts[k], demands[k]);
    const std::size_t before = build.components.size();
    kinds[k]->build(in, build, dofs);
    in.finish();
    dofs.checkAllTaken(in.where() + ": <" + in.tag() + ">");
    for (std::size_t c = before; c < build.components.size(); ++c) elementIndex[build.components[c].get()] = k;
  }
  if (build.layout.total() == 0)
    throw InputError(SourceLocation{scene.label, scene.line, 0}.describe() +
                     ": <metriplex>: the scene has nothing to integrate (no mass, body, solid, thermal element "
                     "or reservoir)");
  setMechanicalScales(build, scene.settings.tEnd);
  std::vector<RedundantConditions> redundant = holdRedundantMultipliers(build.constraints, build.state);
  auto model = std::make_unique<Model>(build.layout, build.variable, std::move(build.components),
                                       build.thermalNodeNames, build.state, build.scale,
                                       std::move(build.prescribedMotions), std::move(build.loadBreakpoints));
  checkInitialState(*model, scene, elementIndex);
  // the model evaluates couplings last: its order, not the build's
  std::vector<std::string> componentElements;
  for (const auto& component : model->components()) {
    const ElementSpec& element = scene.elements[elementIndex.at(component.get())];
    const std::string* name = element.find("name");
    componentElements.push_back(name ? *name : element.tag);
  }
  return {scene.name,
          scene.settings,
          std::move(model),
          std::move(build.bodyFrames),
          std::move(build.jointCoordinates),
          std::move(build.solids),
          std::move(redundant),
          std::move(componentElements)};
}

SceneSpec readScene(const std::string& path) {
  if (std::filesystem::path(path).extension() == ".urdf") return readUrdfScene(path);
  return readXmlScene(readInputFile(path, "scene file"), path);
}

CompiledScene loadScene(const std::string& path, std::optional<ThermalVariable> thermalVariable) {
  return compileScene(readScene(path), thermalVariable);
}

CompiledScene loadSceneText(const std::string& text, const std::string& label,
                            std::optional<ThermalVariable> thermalVariable) {
  return compileScene(readXmlScene(text, label), thermalVariable);
}

}  // namespace mpx
