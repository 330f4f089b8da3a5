#include "models/scene/scene_compiler.hpp"

#include "engine/stepping/method.hpp"
#include "models/lumped/damper.hpp"
#include "models/lumped/external_force.hpp"
#include "models/thermal/fixed_temperature.hpp"
#include "models/multibody/inertia.hpp"

#include <algorithm>

namespace mpx {

namespace {

// Scene elements that own a thermal dof or an internal variable: counted before the main
// pass so the state layout (and thus every global dof index) is known while reading.
bool ownsThermalDof(const std::string& tag) {
  return tag == "thermo_spring" || tag == "thermo_maxwell" || tag == "reservoir";
}
// jointTypes: the type attribute of every <joint> by name (a bushing branch has three).
int internalDofsOf(const XMLElement& element, const std::map<std::string, std::string>& jointTypes) {
  const std::string tag = element.Name();
  if (tag == "maxwell" || tag == "thermo_maxwell") return 1;
  if (tag != "joint_force" || !element.Attribute("branch_stiffness")) return 0;
  const char* joint = element.Attribute("joint");
  const auto type = joint ? jointTypes.find(joint) : jointTypes.end();
  return type != jointTypes.end() && type->second == "spherical" ? 3 : 1;
}

}  // namespace

CompiledScene SceneCompiler::compile() {
  if (std::string(root_.Name()) != "metriplex")
    throw InputError(file_, root_.GetLineNum(),
                     std::string("the root element must be <metriplex>, found <") + root_.Name() + ">");
  readSettings();
  loadSolidMeshes();

  // the layout from a count of what owns dofs
  int positions = 0, thermal = 0, internal = 0, multipliers = 0;
  std::map<std::string, std::string> jointTypes;
  for (const XMLElement* e = root_.FirstChildElement("joint"); e; e = e->NextSiblingElement("joint"))
    if (e->Attribute("name") && e->Attribute("type")) jointTypes[e->Attribute("name")] = e->Attribute("type");
  for (const XMLElement* e = root_.FirstChildElement(); e; e = e->NextSiblingElement()) {
    const std::string tag = e->Name();
    positions += tag == "mass" ? 3 : tag == "body" ? 12 : 0;
    if (tag == "solid") positions += solidPositionDofs(*e, internal);
    thermal += ownsThermalDof(tag);
    internal += internalDofsOf(*e, jointTypes);
    multipliers += multipliersOf(*e);
  }
  layout_ = Layout({positions, positions, thermal, internal, multipliers});
  state_ = Eigen::VectorXd::Zero(layout_.total());
  scale_ = Eigen::VectorXd::Zero(layout_.total());

  for (const XMLElement* e = root_.FirstChildElement(); e; e = e->NextSiblingElement()) addElement(*e);
  if (layout_.total() == 0)
    throw InputError(file_, root_.GetLineNum(),
                     "<metriplex>: the scene has nothing to integrate (no mass, thermal element or reservoir)");

  // Newton's increment scales: a length for positions, length per run time for velocities
  const double length = positionScale_ > 0.0 ? positionScale_ : 1.0;
  for (int i = 0; i < layout_.size(Block::Position); ++i) {
    const int p = layout_.dof(Block::Position, i), v = layout_.dof(Block::Velocity, i);
    scale_[p] = std::max(scale_[p], length);
    scale_[v] = std::max(std::abs(state_[v]), length / settings_.tEnd);
  }
  auto model = std::make_unique<Model>(layout_, variable_, std::move(components_), thermalNodeNames_, state_, scale_,
                                      std::move(prescribedMotions_));
  return {settings_, std::move(model), std::move(bodyFrames_), std::move(jointCoordinates_), std::move(solids_)};
}

void SceneCompiler::readSettings() {
  ElementReader root(root_, file_);
  settings_.name = root.text("name", "scene");
  root.finish();
  bool haveSimulation = false;
  for (const XMLElement* e = root_.FirstChildElement(); e; e = e->NextSiblingElement()) {
    const std::string tag = e->Name();
    ElementReader in(*e, file_);
    if (tag == "simulation") {
      if (haveSimulation) in.fail("a scene has one <simulation> element; this is the second");
      haveSimulation = true;
      readSimulation(in);
    } else if (tag == "solver") {
      readSolver(in);
    } else if (tag == "gravity") {
      gravity_ = in.vector("g", Vec3::Zero());
      in.finish();
    } else if (tag == "constraints") {
      constraintDefaults_ = constraintSettings(in);
      in.finish();
    }
  }
  if (!haveSimulation)
    throw InputError(file_, root_.GetLineNum(), "<metriplex>: missing <simulation dt=... t_end=...> element");
  variable_ = thermalOverride_.value_or(settings_.thermalVariable);
}

void SceneCompiler::readSimulation(ElementReader& in) {
  settings_.dt = in.positive("dt");
  settings_.tEnd = in.positive("t_end");
  settings_.integrator = in.text("integrator", "eem");
  const std::optional<Method> method = methodByName(settings_.integrator);
  if (!method) in.fail("unknown integrator '" + settings_.integrator + "' (choose " + kMethodNames + ")");
  const std::string variable = in.text("thermal_variable", "temperature");
  if (variable != "temperature" && variable != "entropy")
    in.fail("thermal_variable must be 'temperature' or 'entropy', got '" + variable + "'");
  settings_.thermalVariable = variable == "entropy" ? ThermalVariable::Entropy : ThermalVariable::Temperature;
  // an integrator that fixes the thermal variable decides it, unless the scene says otherwise
  if (method->thermalVariable) {
    if (in.has("thermal_variable") && *method->thermalVariable != settings_.thermalVariable)
      in.fail("integrator '" + settings_.integrator + "' contradicts thermal_variable='" + variable + "'");
    settings_.thermalVariable = *method->thermalVariable;
  }
  const std::string form = in.text("discrete_gradient", "partitioned");
  if (form != "partitioned" && form != "gonzalez")
    in.fail("discrete_gradient must be 'partitioned' or 'gonzalez', got '" + form + "'");
  settings_.discreteGradient = form == "gonzalez" ? DiscreteGradientForm::Gonzalez : DiscreteGradientForm::Partitioned;
  in.finish();
}

void SceneCompiler::readSolver(ElementReader& in) {
  NewtonSettings& n = settings_.newton;
  n.incrementTolerance = in.positive("increment_tolerance", n.incrementTolerance);
  n.residualTolerance = in.positive("residual_tolerance", n.residualTolerance);
  n.maxIterations = in.count("max_iterations", n.maxIterations);
  n.maxCutbacks = in.count("max_cutbacks", n.maxCutbacks);
  if (n.maxIterations < 1) in.fail("max_iterations must be at least 1");
  in.finish();
}

void SceneCompiler::addElement(const XMLElement& element) {
  const std::string tag = element.Name();
  ElementReader in(element, file_);
  if (tag == "simulation" || tag == "solver" || tag == "gravity" || tag == "constraints") return;  // readSettings
  if (tag == "mass") addMass(in);
  else if (tag == "anchor") addAnchor(in);
  else if (tag == "spring") addSpring(in, false);
  else if (tag == "maxwell") addSpring(in, true);
  else if (tag == "damper") addDamper(in);
  else if (tag == "thermo_spring") addThermoElement(in, false);
  else if (tag == "thermo_maxwell") addThermoElement(in, true);
  else if (tag == "reservoir") addReservoir(in);
  else if (tag == "fixed_temperature") addFixedTemperature(in);
  else if (tag == "heat_link") addHeatLink(in);
  else if (tag == "force") addForce(in);
  else if (tag == "torque") addTorque(in);
  else if (tag == "body") addBody(in);
  else if (tag == "joint") addJoint(in);
  else if (tag == "joint_force") addJointForce(in);
  else if (tag == "solid") addSolid(in);
  else if (tag == "traction") addTraction(in);
  else if (tag == "body_force") addBodyForce(in);
  else if (tag == "clamp") addPrescribedMotion(in, MotionKind::Clamp);
  else if (tag == "prescribed_velocity") addPrescribedMotion(in, MotionKind::Velocity);
  else if (tag == "prescribed_displacement") addPrescribedMotion(in, MotionKind::Displacement);
  else if (tag == "solid_joint") addSolidJoint(in);
  else in.fail("unknown element (see docs/scene-format.md for the elements a scene may hold)");
  in.finish();
}

std::string SceneCompiler::declareName(ElementReader& in) {
  const std::string name = in.text("name");
  if (name.empty()) in.fail("name must not be empty");
  const auto [it, inserted] = names_.emplace(name, in.line());
  if (!inserted) in.fail("name '" + name + "' is already used on line " + std::to_string(it->second));
  return name;
}

Endpoint SceneCompiler::endpoint(ElementReader& in, const char* attribute) {
  const std::string name = in.text(attribute);
  const auto it = points_.find(name);
  if (it == points_.end())
    in.fail(std::string("attribute '") + attribute + "': no mass or anchor named '" + name +
            "' declared above this element");
  return it->second;
}

Vec3 SceneCompiler::positionOf(const Endpoint& end) const {
  return end.isMass() ? Vec3(state_.segment<3>(end.positionDof)) : end.anchor;
}

std::pair<Endpoint, Endpoint> SceneCompiler::endpoints(ElementReader& in) {
  const Endpoint a = endpoint(in, "a"), b = endpoint(in, "b");
  const double length = (positionOf(b) - positionOf(a)).norm();
  if (!(length > 0.0)) in.fail("end points 'a' and 'b' coincide: the element has no direction");
  keepPositionScale(length);
  return {a, b};
}

ThermalNodeRef SceneCompiler::thermalNode(ElementReader& in, const char* attribute) {
  const std::string name = in.text(attribute);
  const auto it = thermalNodes_.find(name);
  if (it == thermalNodes_.end())
    in.fail(std::string("attribute '") + attribute + "': no thermal node named '" + name +
            "' declared above (thermo_spring, thermo_maxwell, reservoir or fixed_temperature)");
  return it->second;
}

int SceneCompiler::nextThermalDof(const std::string& name, double scale, int& node) {
  const int dof = layout_.dof(Block::Thermal, thermalCount_++);
  node = static_cast<int>(thermalNodeNames_.size());
  thermalNodeNames_.push_back(name);
  thermalNodes_[name] = ThermalNodeRef{node, dof, {}};
  scale_[dof] = scale;
  return dof;
}

void SceneCompiler::addLumpedElement(LumpedElementSpec spec) {
  spec.form = settings_.discreteGradient;
  auto element = std::make_unique<LumpedElement>(std::move(spec));
  if (const auto node = thermalNodes_.find(element->name()); node != thermalNodes_.end())
    node->second.ownerDofs = element->dofs();
  components_.push_back(std::move(element));
}

void SceneCompiler::addMass(ElementReader& in) {
  const std::string name = declareName(in);
  const double mass = in.positive("mass");
  const Endpoint end{layout_.dof(Block::Position, positionCount_), layout_.dof(Block::Velocity, positionCount_),
                     Vec3::Zero()};
  positionCount_ += 3;
  state_.segment<3>(end.positionDof) = in.vector("position", Vec3::Zero());
  state_.segment<3>(end.velocityDof) = in.vector("velocity", Vec3::Zero());
  keepPositionScale(state_.segment<3>(end.positionDof).norm());
  points_[name] = end;
  attachments_[name] = Attachment{Attachment::Kind::Point, end.positionDof, state_.segment<3>(end.positionDof), Mat3::Identity()};
  components_.push_back(
      std::make_unique<Inertia>(name, end.positionDof, end.velocityDof, std::vector<InertiaBlock>{{mass, true}}, gravity_));
}

void SceneCompiler::addAnchor(ElementReader& in) {
  const std::string name = declareName(in);
  Endpoint end;
  end.anchor = in.vector("position", Vec3::Zero());
  keepPositionScale(end.anchor.norm());
  points_[name] = end;
  attachments_[name] = Attachment{Attachment::Kind::Ground, -1, end.anchor, Mat3::Identity()};
}

void SceneCompiler::addSpring(ElementReader& in, bool withBranch) {
  LumpedElementSpec spec;
  spec.name = declareName(in);
  spec.ends = endpoints(in);
  const double stiffness = in.nonNegative("stiffness", 0.0);
  const double restLength = in.positive("rest_length");
  double branchStiffness = 0.0;
  if (withBranch) {
    branchStiffness = in.positive("branch_stiffness");
    spec.viscosity.reference = in.positive("viscosity");
    spec.internalDof = layout_.dof(Block::Internal, internalCount_++);
    state_[spec.internalDof] = in.number("viscous_elongation", 0.0);
    scale_[spec.internalDof] = restLength;
  }
  if (!withBranch && !(stiffness > 0.0)) in.fail("attribute 'stiffness' must be positive");
  keepPositionScale(restLength);
  spec.law = std::make_shared<HookeLaw>(stiffness, restLength, branchStiffness);
  spec.argumentScale = Vec3(restLength * restLength, 1.0, restLength);
  addLumpedElement(std::move(spec));
}

void SceneCompiler::addDamper(ElementReader& in) {
  const std::string name = declareName(in);
  const auto [a, b] = endpoints(in);
  components_.push_back(std::make_unique<Damper>(name, a, b, in.positive("coefficient")));
}

void SceneCompiler::addThermoElement(ElementReader& in, bool withBranch) {
  LumpedElementSpec spec;
  spec.name = declareName(in);
  spec.ends = endpoints(in);
  ThermoElasticParameters p;
  p.stiffness = in.positive("stiffness");
  p.stiffnessSlope = in.number("stiffness_slope", 0.0);
  p.stiffnessCurvature = in.number("stiffness_curvature", 0.0);
  p.coupling = in.number("coupling", 0.0);
  p.restLength = in.positive("rest_length");
  p.heatCapacity = in.positive("heat_capacity");
  p.referenceTemperature = in.positive("reference_temperature");
  keepPositionScale(p.restLength);
  const double thermalScale = variable_ == ThermalVariable::Temperature ? p.referenceTemperature : p.heatCapacity;
  if (withBranch) {
    p.branchStiffness = in.positive("branch_stiffness");
    spec.viscosity = {in.positive("viscosity"), in.number("viscosity_activation", 0.0), p.referenceTemperature};
  }

  std::shared_ptr<ThermoElasticLaw> law;
  try {
    law = std::make_shared<ThermoElasticLaw>(p, variable_);
  } catch (const std::invalid_argument& e) {
    in.fail(e.what());
  }
  spec.law = law;
  spec.thermalDof = nextThermalDof(spec.name, thermalScale, spec.thermalNode);
  const double gamma = withBranch ? in.number("viscous_strain", 0.0) : 0.0;
  if (withBranch) {
    spec.internalDof = layout_.dof(Block::Internal, internalCount_++);
    state_[spec.internalDof] = gamma;
    scale_[spec.internalDof] = 1.0;
  }

  // initial thermal state from a temperature or an entropy, in the model's variable
  const double c = (positionOf(spec.ends->second) - positionOf(spec.ends->first)).squaredNorm();
  if (in.has("temperature") == in.has("entropy")) in.fail("give exactly one of 'temperature' and 'entropy'");
  try {
    state_[spec.thermalDof] = in.has("temperature")
                                  ? law->thermalVariableFromTemperature(c, in.positive("temperature"), gamma)
                                  : law->thermalVariableFromEntropy(c, in.number("entropy"), gamma);
  } catch (const std::invalid_argument& e) {
    in.fail(e.what());
  }
  spec.argumentScale = Vec3(p.restLength * p.restLength, thermalScale, 1.0);
  addLumpedElement(std::move(spec));
}

void SceneCompiler::addReservoir(ElementReader& in) {
  LumpedElementSpec spec;
  spec.name = declareName(in);
  ThermoElasticParameters p;
  p.hasStretch = false;
  p.heatCapacity = in.positive("heat_capacity");
  if (in.has("temperature") == in.has("entropy")) in.fail("give exactly one of 'temperature' and 'entropy'");
  p.referenceTemperature = in.positive("reference_temperature", in.has("temperature") ? in.positive("temperature") : 1.0);
  const auto law = std::make_shared<ThermoElasticLaw>(p, variable_);
  spec.law = law;
  const double thermalScale = variable_ == ThermalVariable::Temperature ? p.referenceTemperature : p.heatCapacity;
  spec.thermalDof = nextThermalDof(spec.name, thermalScale, spec.thermalNode);
  try {
    state_[spec.thermalDof] = in.has("temperature")
                                  ? law->thermalVariableFromTemperature(0.0, in.positive("temperature"), 0.0)
                                  : law->thermalVariableFromEntropy(0.0, in.number("entropy"), 0.0);
  } catch (const std::invalid_argument& e) {
    in.fail(e.what());
  }
  spec.argumentScale = Vec3(1.0, thermalScale, 1.0);
  addLumpedElement(std::move(spec));
}

void SceneCompiler::addFixedTemperature(ElementReader& in) {
  const std::string name = declareName(in);
  const int node = static_cast<int>(thermalNodeNames_.size());
  thermalNodeNames_.push_back(name);
  thermalNodes_[name] = ThermalNodeRef{node, -1, {}};
  components_.push_back(std::make_unique<FixedTemperature>(name, node, in.positive("temperature")));
}

void SceneCompiler::addHeatLink(ElementReader& in) {
  const std::string name = declareName(in);
  ThermalNodeRef a = thermalNode(in, "a"), b = thermalNode(in, "b");
  if (a.node == b.node) in.fail("a heat link needs two different thermal nodes");
  if (a.thermalDof < 0 && b.thermalDof < 0) in.fail("a heat link between two fixed temperatures has no effect");
  components_.push_back(std::make_unique<HeatLink>(name, std::move(a), std::move(b), in.positive("conductivity")));
}

TimeFunction readProfile(ElementReader& in) {
  const std::string profile = in.text("profile", "constant");
  if (profile == "constant") return TimeFunction::constant();
  if (profile == "ramp") {
    const double start = in.nonNegative("start", 0.0), end = in.positive("end");
    if (!(end > start)) in.fail("ramp needs end > start");
    return TimeFunction::ramp(start, end);
  }
  if (profile == "hat") return TimeFunction::hat(in.positive("period"));
  if (profile == "sine_pulse") return TimeFunction::sinePulse(in.positive("duration"));
  if (profile == "table") {
    std::vector<double> times = in.numbers("times"), values = in.numbers("values");
    if (times.empty() || times.size() != values.size()) in.fail("'times' and 'values' need the same, non-zero count");
    if (!std::is_sorted(times.begin(), times.end(), std::less_equal<>()) ||
        std::adjacent_find(times.begin(), times.end()) != times.end())
      in.fail("'times' must be strictly increasing");
    return TimeFunction::table(std::move(times), std::move(values));
  }
  in.fail("profile must be constant, ramp, hat, sine_pulse or table, got '" + profile + "'");
}

void SceneCompiler::addForce(ElementReader& in) {
  const std::string name = declareName(in);
  const Endpoint on = endpoint(in, "on");
  if (!on.isMass()) in.fail("attribute 'on' must name a mass or a body (its centre of mass), not an anchor");
  const Vec3 force = in.vector("force", Vec3::Zero());
  components_.push_back(std::make_unique<ExternalForce>(name, on.positionDof, on.velocityDof, force, readProfile(in)));
}

}  // namespace mpx
