// Thermal nodes and what connects them: thermo-springs, thermo-visco-elastic Maxwell elements,
// heat reservoirs, fixed temperatures and heat links (docs/scene-format.md).
#include "models/lumped/element_laws.hpp"
#include "models/lumped/lumped_element.hpp"
#include "models/scene/scene_build.hpp"
#include "models/thermal/fixed_temperature.hpp"
#include "models/thermal/heat_link.hpp"

namespace mpx {

namespace {

double thermalScale(const SceneBuild& build, const ThermoElasticParameters& p) {
  return build.variable == ThermalVariable::Temperature ? p.referenceTemperature : p.heatCapacity;
}

// The initial thermal variable, in the model's variable, from temperature="..." or entropy="...".
double initialThermalState(ElementReader& in, const ThermoElasticLaw& law, double c, double gamma) {
  if (in.has("temperature") == in.has("entropy")) in.fail("give exactly one of 'temperature' and 'entropy'");
  try {
    return in.has("temperature") ? law.thermalVariableFromTemperature(c, in.positive("temperature"), gamma)
                                 : law.thermalVariableFromEntropy(c, in.number("entropy"), gamma);
  } catch (const std::invalid_argument& e) {
    in.fail(e.what());
  }
}

// <thermo_spring> and <thermo_maxwell>.
void buildThermoElement(ElementReader& in, SceneBuild& build, DofRange& dofs, bool withBranch) {
  LumpedElementSpec spec;
  spec.name = build.declareName(in);
  spec.ends = build.endpoints(in);
  spec.form = build.spec.settings.discreteGradient;
  ThermoElasticParameters p;
  p.stiffness = in.positive("stiffness");
  p.stiffnessSlope = in.number("stiffness_slope", 0.0);
  p.stiffnessCurvature = in.number("stiffness_curvature", 0.0);
  p.coupling = in.number("coupling", 0.0);
  p.restLength = in.positive("rest_length");
  p.heatCapacity = in.positive("heat_capacity");
  p.referenceTemperature = in.positive("reference_temperature");
  build.keepPositionScale(p.restLength);
  if (withBranch) {
    p.branchStiffness = in.positive("branch_stiffness");
    spec.viscosity = {in.positive("viscosity"), in.number("viscosity_activation", 0.0), p.referenceTemperature};
  }
  std::shared_ptr<ThermoElasticLaw> law;
  try {
    law = std::make_shared<ThermoElasticLaw>(p, build.variable);
  } catch (const std::invalid_argument& e) {
    in.fail(e.what());
  }
  spec.law = law;
  spec.thermalDof = dofs.take(Block::Thermal, 1);
  spec.thermalNode = build.addThermalNode(spec.name, spec.thermalDof, thermalScale(build, p));
  const double gamma = withBranch ? in.number("viscous_strain", 0.0) : 0.0;
  if (withBranch) {
    spec.internalDof = dofs.take(Block::Internal, 1);
    build.state[spec.internalDof] = gamma;
    build.scale[spec.internalDof] = 1.0;
  }
  const double c = (build.positionOf(spec.ends->second) - build.positionOf(spec.ends->first)).squaredNorm();
  build.state[spec.thermalDof] = initialThermalState(in, *law, c, gamma);
  spec.argumentScale = Vec3(p.restLength * p.restLength, thermalScale(build, p), 1.0);
  const std::string node = spec.name;
  build.addThermalNodeOwner(node, std::make_unique<LumpedElement>(std::move(spec)));
}

void buildReservoir(ElementReader& in, SceneBuild& build, DofRange& dofs) {
  LumpedElementSpec spec;
  spec.name = build.declareName(in);
  spec.form = build.spec.settings.discreteGradient;
  ThermoElasticParameters p;
  p.hasStretch = false;
  p.heatCapacity = in.positive("heat_capacity");
  if (in.has("temperature") == in.has("entropy")) in.fail("give exactly one of 'temperature' and 'entropy'");
  p.referenceTemperature =
      in.positive("reference_temperature", in.has("temperature") ? in.positive("temperature") : 1.0);
  const auto law = std::make_shared<ThermoElasticLaw>(p, build.variable);
  spec.law = law;
  spec.thermalDof = dofs.take(Block::Thermal, 1);
  spec.thermalNode = build.addThermalNode(spec.name, spec.thermalDof, thermalScale(build, p));
  build.state[spec.thermalDof] = initialThermalState(in, *law, 0.0, 0.0);
  spec.argumentScale = Vec3(1.0, thermalScale(build, p), 1.0);
  const std::string node = spec.name;
  build.addThermalNodeOwner(node, std::make_unique<LumpedElement>(std::move(spec)));
}

void buildFixedTemperature(ElementReader& in, SceneBuild& build, DofRange&) {
  const std::string name = build.declareName(in);
  const int node = build.addThermalNode(name, -1, 0.0);
  build.addComponent(std::make_unique<FixedTemperature>(name, node, in.positive("temperature")));
}

void buildHeatLink(ElementReader& in, SceneBuild& build, DofRange&) {
  const std::string name = build.declareName(in);
  ThermalNodeRef a = build.thermalNode(in, "a"), b = build.thermalNode(in, "b");
  if (a.node == b.node) in.fail("a heat link needs two different thermal nodes");
  if (a.thermalDof < 0 && b.thermalDof < 0) in.fail("a heat link between two fixed temperatures has no effect");
  build.addComponent(std::make_unique<HeatLink>(name, std::move(a), std::move(b), in.positive("conductivity")));
}

}  // namespace

const std::vector<ElementKind>& thermalElementKinds() {
  static const std::vector<ElementKind> kinds = {
      {"thermo_spring",
       [](ElementReader&, SceneBuild&) {
         return DofDemand{0, 1, 0, 0};
       },
       [](ElementReader& in, SceneBuild& b, DofRange& d) { buildThermoElement(in, b, d, false); }},
      {"thermo_maxwell",
       [](ElementReader&, SceneBuild&) {
         return DofDemand{0, 1, 1, 0};
       },
       [](ElementReader& in, SceneBuild& b, DofRange& d) { buildThermoElement(in, b, d, true); }},
      {"reservoir",
       [](ElementReader&, SceneBuild&) {
         return DofDemand{0, 1, 0, 0};
       },
       buildReservoir},
      {"fixed_temperature", nullptr, buildFixedTemperature},
      {"heat_link", nullptr, buildHeatLink},
  };
  return kinds;
}

}  // namespace mpx
