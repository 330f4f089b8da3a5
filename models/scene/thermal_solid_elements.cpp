// Thermal fields of finite-element solids: the thermal material of a <solid>, initial and
// prescribed temperatures, heat flux and convection on named surfaces (docs/scene-format.md,
// "Thermal solids").
#include "models/scene/scene_build.hpp"
#include "models/thermal/surface_heat.hpp"
#include "models/thermal/surface_heat_link.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace mpx {

std::optional<ThermalMaterial> readThermalMaterial(ElementReader& in, const LameParameters& lame) {
  if (!in.has("heat_capacity")) {
    for (const char* attribute :
         {"conductivity", "expansion", "reference_temperature", "temperature", "viscosity_activation"})
      if (in.has(attribute)) in.fail(fmt::format("'{}' needs a thermal solid: give heat_capacity too", attribute));
    return std::nullopt;
  }
  ThermalMaterial m;
  m.capacity = in.positive("heat_capacity");
  m.conductivity = in.nonNegative("conductivity", 0.0);
  m.expansion = in.number("expansion", 0.0);
  m.referenceTemperature = in.positive("reference_temperature", 293.15);
  if (in.has("viscosity_activation") && !in.has("viscosity"))
    in.fail("'viscosity_activation' needs a viscous branch: give viscosity too");
  m.viscosityActivation = in.number("viscosity_activation", 0.0);
  m.bulkModulus = lame.lambda + 2.0 * lame.mu / 3.0;
  return m;
}

void takeTemperatures(ElementReader& in, SceneBuild& build, DofRange& dofs, const ThermalMaterial& m,
                      SolidPlacement& solid) {
  const double temperature = in.positive("temperature", m.referenceTemperature);
  const int nodes = static_cast<int>(solid.mesh->nodes.size()), first = dofs.take(Block::Thermal, nodes);
  solid.thermalVariable = NodalThermalVariable(build.variable, m.capacity, m.referenceTemperature);
  for (int n = 0; n < nodes; ++n) {
    const int dof = first + n;
    solid.thermalDofs.push_back(dof);
    build.state[dof] = solid.thermalVariable.fromTemperature(temperature);
    build.scale[dof] = solid.thermalVariable.scale();
  }
}

namespace {

// The thermal solid named by 'solid'.
const SolidPlacement& thermalSolidOf(ElementReader& in, const SceneBuild& build) {
  const SolidPlacement& solid = build.solidOf(in);
  if (solid.thermalDofs.empty()) in.fail("solid '" + solid.name + "' has no temperature field (give it heat_capacity)");
  return solid;
}

bool hasPrescribedTemperature(const SceneBuild& build, int dof) {
  return std::any_of(build.prescribedMotions.begin(), build.prescribedMotions.end(),
                     [&](const PrescribedMotion& p) { return p.dof == dof; });
}

void buildInitialTemperature(ElementReader& in, SceneBuild& build, DofRange&) {
  const SolidPlacement& solid = thermalSolidOf(in, build);
  const double temperature = in.positive("temperature");
  // a held node starts at its prescribed value; the row only imposes its change
  for (int node : build.solidNodes(in, solid)) {
    const int dof = solid.thermalDofs[node];
    if (hasPrescribedTemperature(build, dof))
      in.fail(
          fmt::format("node {} of '{}' has a prescribed temperature, which is also its initial one", node, solid.name));
    build.state[dof] = solid.thermalVariable.fromTemperature(temperature);
  }
}

// Dirichlet: the nodes' heat rows become theta = temperature * profile(t), and their reactions
// are the heat that enters there.
void buildPrescribedTemperature(ElementReader& in, SceneBuild& build, DofRange&) {
  const SolidPlacement& solid = thermalSolidOf(in, build);
  if (build.variable == ThermalVariable::Entropy)
    in.fail(
        "a prescribed temperature needs the temperature form (the entropy form's dofs are entropies: run "
        "eem-temperature or set thermal_variable=\"temperature\")");
  const std::vector<int> nodes = build.solidNodes(in, solid);
  const double temperature = in.positive("temperature");
  const TimeFunction profile = readProfile(in, build);
  if (!(profile(0.0) > 0.0)) in.fail("the prescribed temperature must be positive at t = 0");
  for (int node : nodes) {
    const int dof = solid.thermalDofs[node];
    if (hasPrescribedTemperature(build, dof))
      in.fail(fmt::format("node {} of '{}' already has a prescribed temperature", node, solid.name));
    build.prescribedMotions.push_back(
        {dof, temperature, profile, PrescribedKind::Temperature, in.where() + ": <" + in.tag() + ">"});
    build.state[dof] = temperature * profile(0.0);
  }
}

// int N_a dA of each node of the thermal solid's surface named by 'surface'.
std::map<int, double> thermalSurfaceAreas(ElementReader& in, const SolidPlacement& solid) {
  const std::string surface = in.text("surface");
  const auto faces = solid.mesh->surfaces.find(surface);
  if (faces == solid.mesh->surfaces.end())
    in.fail("attribute 'surface': the mesh of '" + solid.name + "' has no surface '" + surface + "'");
  return surfaceNodeAreas(*solid.mesh, faces->second);
}

// One SurfaceHeat per node of the surface, with its share of the area.
void addSurfaceHeat(ElementReader& in, SceneBuild& build, SurfaceHeatSpec spec) {
  const SolidPlacement& solid = thermalSolidOf(in, build);
  const std::string name = spec.name;
  for (const auto& [node, area] : thermalSurfaceAreas(in, solid)) {
    spec.name = name + ".node" + std::to_string(node);
    spec.thermalDof = solid.thermalDofs[node];
    spec.thermalVariable = solid.thermalVariable;
    spec.area = area;
    build.addComponent(std::make_unique<SurfaceHeat>(spec));
  }
}

void buildHeatFlux(ElementReader& in, SceneBuild& build, DofRange&) {
  SurfaceHeatSpec spec;
  spec.name = build.declareName(in);
  spec.flux = in.number("flux");
  spec.profile = readProfile(in, build);
  addSurfaceHeat(in, build, spec);
}

void buildConvection(ElementReader& in, SceneBuild& build, DofRange&) {
  SurfaceHeatSpec spec;
  spec.name = build.declareName(in);
  spec.convection = in.positive("coefficient");
  spec.ambientTemperature = in.positive("ambient");
  addSurfaceHeat(in, build, spec);
}

// One SurfaceHeatLink per node of the surface to the lumped thermal node 'node'.
void buildSurfaceHeatLink(ElementReader& in, SceneBuild& build, DofRange&) {
  const std::string name = build.declareName(in);
  const SolidPlacement& solid = thermalSolidOf(in, build);
  const ThermalNodeRef lumped = build.thermalNode(in, "node");
  const double coefficient = in.positive("coefficient");
  for (const auto& [node, area] : thermalSurfaceAreas(in, solid))
    build.addComponent(std::make_unique<SurfaceHeatLink>(name + ".node" + std::to_string(node), solid.thermalDofs[node],
                                                         solid.thermalVariable, lumped, coefficient * area));
}

}  // namespace

const std::vector<ElementKind>& thermalSolidElementKinds() {
  static const std::vector<ElementKind> kinds = {
      {"initial_temperature", nullptr, buildInitialTemperature},
      {"prescribed_temperature", nullptr, buildPrescribedTemperature},
      {"heat_flux", nullptr, buildHeatFlux},
      {"convection", nullptr, buildConvection},
      {"surface_heat_link", nullptr, buildSurfaceHeatLink},
  };
  return kinds;
}

}  // namespace mpx
