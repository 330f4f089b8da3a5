#include "scene_loader.hpp"

#include "element_reader.hpp"
#include "engine/method.hpp"
#include "models/damper.hpp"
#include "models/external_force.hpp"
#include "models/external_torque.hpp"
#include "models/fixed_temperature.hpp"
#include "models/heat_link.hpp"
#include "models/inertia.hpp"
#include "models/joint_builder.hpp"
#include "models/joint_force.hpp"
#include "urdf_scene.hpp"

#include <algorithm>
#include <Eigen/Eigenvalues>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace mpx {

namespace {

using tinyxml2::XMLElement;

// Scene elements that own a thermal dof or an internal variable: counted before the main
// pass so the state layout (and thus every global dof index) is known while reading.
bool ownsThermalDof(const std::string& tag) {
  return tag == "thermo_spring" || tag == "thermo_maxwell" || tag == "reservoir";
}
bool ownsInternalDof(const XMLElement& element) {
  const std::string tag = element.Name();
  return tag == "maxwell" || tag == "thermo_maxwell" ||
         (tag == "joint_force" && element.Attribute("branch_stiffness") != nullptr);
}

// How a set of constraints is enforced.
struct ConstraintSettings {
  Enforcement enforcement = Enforcement::AugmentedLagrangian;
  double stiffness = 1e6;
};

class SceneCompiler {
 public:
  SceneCompiler(const XMLElement& root, std::string file, std::optional<ThermalVariable> thermalVariable)
      : root_(root), file_(std::move(file)), thermalOverride_(thermalVariable) {}

  CompiledScene compile();

 private:
  void readSettings();
  void readSimulation(ElementReader& in);
  void readSolver(ElementReader& in);
  void addElement(const XMLElement& element);
  void addMass(ElementReader& in);
  void addAnchor(ElementReader& in);
  void addSpring(ElementReader& in, bool withBranch);
  void addDamper(ElementReader& in);
  void addThermoElement(ElementReader& in, bool withBranch);
  void addReservoir(ElementReader& in);
  void addFixedTemperature(ElementReader& in);
  void addHeatLink(ElementReader& in);
  void addForce(ElementReader& in);
  void addTorque(ElementReader& in);
  void addBody(ElementReader& in);
  void addJoint(ElementReader& in);
  void addJointForce(ElementReader& in);
  // Penalty or augmented-Lagrangian enforcement of `forms`, with multipliers when needed.
  void addConstraint(const std::string& name, const JointBuilder& builder, std::vector<QuadraticForm> forms,
                     const ConstraintSettings& settings);
  ConstraintSettings constraintSettings(ElementReader& in);
  // Scalar constraints an element adds to the multiplier block (pre-pass count).
  int multipliersOf(const XMLElement& element) const;

  std::string declareName(ElementReader& in);
  Endpoint endpoint(ElementReader& in, const char* attribute);
  std::pair<Endpoint, Endpoint> endpoints(ElementReader& in);
  ThermalNodeRef thermalNode(ElementReader& in, const char* attribute);
  int nextThermalDof(const std::string& name, double scale, int& node);
  // Add a lumped element; its local dofs are what its published node temperature refers to.
  void addLumpedElement(LumpedElementSpec spec);
  Vec3 positionOf(const Endpoint& end) const;
  void keepPositionScale(double length) { positionScale_ = std::max(positionScale_, length); }

  const XMLElement& root_;
  std::string file_;
  std::optional<ThermalVariable> thermalOverride_;
  SceneSettings settings_;
  ThermalVariable variable_ = ThermalVariable::Temperature;
  Vec3 gravity_ = Vec3::Zero();

  Layout layout_;
  Eigen::VectorXd state_, scale_;
  std::vector<std::unique_ptr<Component>> components_;
  std::vector<std::string> thermalNodeNames_;
  std::map<std::string, Endpoint> points_;  // masses and anchors
  std::map<std::string, ThermalNodeRef> thermalNodes_;
  std::map<std::string, int> names_;  // every declared name -> line
  std::map<std::string, Attachment> attachments_;  // what joints may attach to
  // Joints by name, for the force elements on their coordinates.
  struct DeclaredJoint {
    JointType type;
    Attachment a, b;
    JointGeometry geometry;
    double coordinate;  // the joint coordinate's value at t = 0 in the user's convention
  };
  std::map<std::string, DeclaredJoint> joints_;
  std::vector<BodyFrame> bodyFrames_;
  std::vector<JointCoordinate> jointCoordinates_;
  ConstraintSettings constraintDefaults_;
  int positionCount_ = 0, thermalCount_ = 0, internalCount_ = 0, multiplierCount_ = 0;
  double positionScale_ = 0.0;
};

CompiledScene SceneCompiler::compile() {
  if (std::string(root_.Name()) != "metriplex")
    throw InputError(file_, root_.GetLineNum(),
                     std::string("the root element must be <metriplex>, found <") + root_.Name() + ">");
  readSettings();

  // the layout from a count of what owns dofs
  int positions = 0, thermal = 0, internal = 0, multipliers = 0;
  for (const XMLElement* e = root_.FirstChildElement(); e; e = e->NextSiblingElement()) {
    const std::string tag = e->Name();
    positions += tag == "mass" ? 3 : tag == "body" ? 12 : 0;
    thermal += ownsThermalDof(tag);
    internal += ownsInternalDof(*e);
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
  auto model = std::make_unique<Model>(layout_, variable_, std::move(components_), thermalNodeNames_, state_, scale_);
  return {settings_, std::move(model), std::move(bodyFrames_), std::move(jointCoordinates_)};
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

// The time function of a load: profile="constant|ramp|hat|table" and its parameters.
TimeFunction readProfile(ElementReader& in) {
  const std::string profile = in.text("profile", "constant");
  if (profile == "constant") return TimeFunction::constant();
  if (profile == "ramp") {
    const double start = in.nonNegative("start", 0.0), end = in.positive("end");
    if (!(end > start)) in.fail("ramp needs end > start");
    return TimeFunction::ramp(start, end);
  }
  if (profile == "hat") return TimeFunction::hat(in.positive("period"));
  if (profile == "table") {
    std::vector<double> times = in.numbers("times"), values = in.numbers("values");
    if (times.empty() || times.size() != values.size()) in.fail("'times' and 'values' need the same, non-zero count");
    if (!std::is_sorted(times.begin(), times.end(), std::less_equal<>()) ||
        std::adjacent_find(times.begin(), times.end()) != times.end())
      in.fail("'times' must be strictly increasing");
    return TimeFunction::table(std::move(times), std::move(values));
  }
  in.fail("profile must be constant, ramp, hat or table, got '" + profile + "'");
}

void SceneCompiler::addForce(ElementReader& in) {
  const std::string name = declareName(in);
  const Endpoint on = endpoint(in, "on");
  if (!on.isMass()) in.fail("attribute 'on' must name a mass or a body (its centre of mass), not an anchor");
  const Vec3 force = in.vector("force", Vec3::Zero());
  components_.push_back(std::make_unique<ExternalForce>(name, on.positionDof, on.velocityDof, force, readProfile(in)));
}

void SceneCompiler::addTorque(ElementReader& in) {
  const std::string name = declareName(in);
  const std::string target = in.text("on");
  const auto body = attachments_.find(target);
  if (body == attachments_.end() || body->second.kind != Attachment::Kind::Body)
    in.fail("attribute 'on': no body named '" + target + "' declared above this element");
  const Vec3 torque = in.vector("torque", Vec3::Zero());
  components_.push_back(std::make_unique<ExternalTorque>(
      name, body->second.firstPositionDof + 3, layout_.offset(Block::Velocity) - layout_.offset(Block::Position), torque,
      readProfile(in)));
}

ConstraintSettings SceneCompiler::constraintSettings(ElementReader& in) {
  ConstraintSettings settings = constraintDefaults_;
  const std::string enforcement = in.text("enforcement", settings.enforcement == Enforcement::Penalty ? "penalty" : "augmented_lagrangian");
  if (enforcement != "penalty" && enforcement != "augmented_lagrangian")
    in.fail("enforcement must be 'penalty' or 'augmented_lagrangian', got '" + enforcement + "'");
  settings.enforcement = enforcement == "penalty" ? Enforcement::Penalty : Enforcement::AugmentedLagrangian;
  settings.stiffness = in.positive("stiffness", settings.stiffness);
  return settings;
}

int SceneCompiler::multipliersOf(const XMLElement& element) const {
  const std::string tag = element.Name();
  if (tag != "body" && tag != "joint") return 0;
  const char* enforcement = element.Attribute("enforcement");
  const bool augmented = enforcement ? std::string(enforcement) == "augmented_lagrangian"
                                     : constraintDefaults_.enforcement == Enforcement::AugmentedLagrangian;
  if (!augmented) return 0;
  // two multipliers per constraint: lambda, and mu of the rate form (GGL)
  if (tag == "body") return 2 * 6;
  const char* type = element.Attribute("type");
  const std::optional<JointType> joint = type ? jointTypeByName(type) : std::nullopt;
  return joint ? 2 * constraintCount(*joint) : 0;  // a bad type is reported when the joint is read
}

void SceneCompiler::addConstraint(const std::string& name, const JointBuilder& builder,
                                  std::vector<QuadraticForm> forms, const ConstraintSettings& settings) {
  ConstraintSpec spec;
  spec.name = name;
  spec.positionDofs = builder.positionDofs();
  spec.velocityShift = layout_.offset(Block::Velocity) - layout_.offset(Block::Position);
  spec.enforcement = settings.enforcement;
  spec.stiffness = settings.stiffness;
  if (settings.enforcement == Enforcement::AugmentedLagrangian) {
    spec.firstMultiplierDof = layout_.dof(Block::Multiplier, multiplierCount_);
    for (std::size_t k = 0; k < 2 * forms.size(); ++k) scale_[spec.firstMultiplierDof + k] = 1.0;
    multiplierCount_ += 2 * static_cast<int>(forms.size());
  }
  spec.forms = std::move(forms);
  components_.push_back(std::make_unique<QuadraticConstraint>(std::move(spec)));
}

void SceneCompiler::addBody(ElementReader& in) {
  const std::string name = declareName(in);
  const double mass = in.positive("mass");
  const std::vector<double> inertia = in.numbers("inertia");
  if (inertia.size() != 3 && inertia.size() != 6)
    in.fail("inertia needs 3 (Ixx Iyy Izz) or 6 (Ixx Iyy Izz Ixy Ixz Iyz) numbers, got " +
            std::to_string(inertia.size()));
  Mat3 tensor = Vec3(inertia[0], inertia[1], inertia[2]).asDiagonal();
  if (inertia.size() == 6) {
    tensor(0, 1) = tensor(1, 0) = inertia[3];
    tensor(0, 2) = tensor(2, 0) = inertia[4];
    tensor(1, 2) = tensor(2, 1) = inertia[5];
  }
  const Eigen::Quaterniond orientation = in.orientation("orientation");
  const Vec3 position = in.vector("position", Vec3::Zero());
  const Vec3 velocity = in.vector("velocity", Vec3::Zero());
  const Vec3 angularVelocity = in.vector("angular_velocity", Vec3::Zero());
  const ConstraintSettings rigidity = constraintSettings(in);

  // principal axes of the inertia tensor (given in the body frame) become the directors
  const Mat3 rotation = orientation.toRotationMatrix();
  const Eigen::SelfAdjointEigenSolver<Mat3> principal(rotation * tensor * rotation.transpose());
  const Vec3 J = principal.eigenvalues();
  Mat3 directors = principal.eigenvectors();
  if (directors.determinant() < 0) directors.col(2) *= -1.0;
  if (!(J.minCoeff() > 0.0)) in.fail("the inertia tensor must be positive definite");
  const Vec3 E(0.5 * (J[1] + J[2] - J[0]), 0.5 * (J[2] + J[0] - J[1]), 0.5 * (J[0] + J[1] - J[2]));
  if (!(E.minCoeff() > 0.0))
    in.fail("principal moments must satisfy the strict triangle inequality J_i < J_j + J_k "
            "(the director mass matrix needs (J_j + J_k - J_i)/2 > 0)");

  const int phi = layout_.dof(Block::Position, positionCount_), phiRate = layout_.dof(Block::Velocity, positionCount_);
  positionCount_ += 12;
  state_.segment<3>(phi) = position;
  state_.segment<3>(phiRate) = velocity;
  for (int i = 0; i < 3; ++i) {
    state_.segment<3>(phi + 3 + 3 * i) = directors.col(i);
    state_.segment<3>(phiRate + 3 + 3 * i) = angularVelocity.cross(directors.col(i));
  }
  keepPositionScale(position.norm());
  points_[name] = Endpoint{phi, phiRate, Vec3::Zero()};
  attachments_[name] = Attachment{Attachment::Kind::Body, phi, position, directors};
  bodyFrames_.push_back({name, phi, directors.transpose() * rotation});
  components_.push_back(std::make_unique<Inertia>(
      name, phi, phiRate, std::vector<InertiaBlock>{{mass, true}, {E[0], false}, {E[1], false}, {E[2], false}},
      gravity_));
  const JointBuilder builder(attachments_[name], Attachment{});
  addConstraint(name + ".rigidity", builder, builder.rigidity(), rigidity);
}

void SceneCompiler::addJoint(ElementReader& in) {
  const std::string name = declareName(in);
  const std::string typeName = in.text("type");
  const std::optional<JointType> type = jointTypeByName(typeName);
  if (!type)
    in.fail("unknown joint type '" + typeName +
            "' (choose " + kJointTypeNames + ")");
  auto attachment = [&](const char* attribute) {
    const std::string target = in.text(attribute);
    const auto it = attachments_.find(target);
    if (it == attachments_.end())
      in.fail(std::string("attribute '") + attribute + "': no body, mass or anchor named '" + target +
              "' declared above this element");
    return it->second;
  };
  const Attachment a = attachment("a"), b = attachment("b");
  JointGeometry geometry;
  geometry.anchor = in.vector("anchor", b.position);
  geometry.anchorB = in.vector("anchor_b", b.position);
  geometry.axis = in.vector("axis", Vec3::UnitZ());
  geometry.axisB = in.vector("axis_b", Vec3::UnitX());
  if (!(geometry.axis.norm() > 0.0) || !(geometry.axisB.norm() > 0.0)) in.fail("joint axes must be non-zero");
  geometry.axis.normalize();
  geometry.axisB.normalize();
  if (*type == JointType::Distance && !((geometry.anchor - geometry.anchorB).norm() > 0.0))
    in.fail("a distance joint needs anchor and anchor_b apart");
  const double coordinate = in.number("coordinate", 0.0);
  const ConstraintSettings settings = constraintSettings(in);
  const JointBuilder builder(a, b);
  try {
    addConstraint(name, builder, builder.joint(*type, geometry), settings);
  } catch (const std::invalid_argument& e) {
    in.fail(e.what());
  }
  joints_[name] = DeclaredJoint{*type, a, b, geometry, coordinate};
  if (*type == JointType::Revolute || *type == JointType::Prismatic)
    jointCoordinates_.emplace_back(name, *type == JointType::Revolute, builder.positionDofs(),
                                   layout_.offset(Block::Velocity) - layout_.offset(Block::Position),
                                   builder.coordinateInvariants(*type, geometry), coordinate);
}

void SceneCompiler::addJointForce(ElementReader& in) {
  JointForceSpec spec;
  spec.name = declareName(in);
  const std::string jointName = in.text("joint");
  const auto joint = joints_.find(jointName);
  if (joint == joints_.end()) in.fail("attribute 'joint': no joint named '" + jointName + "' declared above");
  if (joint->second.type != JointType::Revolute && joint->second.type != JointType::Prismatic)
    in.fail("joint '" + jointName + "' is not revolute or prismatic: joint forces act on those coordinates");
  const JointBuilder builder(joint->second.a, joint->second.b);
  spec.revolute = joint->second.type == JointType::Revolute;
  spec.positionDofs = builder.positionDofs();
  spec.velocityShift = layout_.offset(Block::Velocity) - layout_.offset(Block::Position);
  spec.invariants = builder.coordinateInvariants(joint->second.type, joint->second.geometry);
  spec.stiffness = in.nonNegative("stiffness", 0.0);
  spec.rest = in.number("rest", joint->second.coordinate) - joint->second.coordinate;
  spec.cubicStiffness = in.nonNegative("cubic_stiffness", 0.0);
  if (spec.revolute && spec.cubicStiffness > 0.0) in.fail("cubic_stiffness applies to prismatic joints only");
  if (in.has("branch_stiffness")) {
    spec.branchStiffness = in.positive("branch_stiffness");
    spec.viscosity = in.positive("viscosity");
    spec.internalDof = layout_.dof(Block::Internal, internalCount_++);
    scale_[spec.internalDof] = 1.0;
  }
  spec.damping = in.nonNegative("damping", 0.0);
  spec.friction = in.nonNegative("friction", 0.0);
  spec.frictionVelocity = in.positive("friction_velocity", 1e-2);
  if (in.has("heat_node")) {
    const ThermalNodeRef node = thermalNode(in, "heat_node");
    if (node.thermalDof < 0) in.fail("heat_node must have a heat capacity (not a fixed temperature)");
    spec.heatDof = node.thermalDof;
  }
  components_.push_back(std::make_unique<JointForce>(std::move(spec)));
}

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
