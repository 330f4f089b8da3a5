#include "models/scene/scene_compiler.hpp"

#include "models/multibody/external_torque.hpp"
#include "models/multibody/inertia.hpp"
#include "models/multibody/joint_force.hpp"

#include <Eigen/Eigenvalues>

namespace mpx {

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
  if (tag != "body" && tag != "joint" && tag != "solid_joint") return 0;
  const char* enforcement = element.Attribute("enforcement");
  const bool augmented = enforcement ? std::string(enforcement) == "augmented_lagrangian"
                                     : constraintDefaults_.enforcement == Enforcement::AugmentedLagrangian;
  if (!augmented) return 0;
  // two multipliers per constraint: lambda, and mu of the rate form (GGL)
  if (tag == "body") return 2 * 6;
  if (tag == "solid_joint") return 2 * 3 * solidJointNodes(element);
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
  const JointType type = joint->second.type;
  if (type != JointType::Revolute && type != JointType::Prismatic && type != JointType::Spherical)
    in.fail("joint '" + jointName + "' is not revolute, prismatic or spherical: joint forces act on those");
  const JointBuilder builder(joint->second.a, joint->second.b);
  spec.revolute = type == JointType::Revolute;
  spec.positionDofs = builder.positionDofs();
  spec.velocityShift = layout_.offset(Block::Velocity) - layout_.offset(Block::Position);
  std::vector<QuadraticForm> invariants;
  try {
    invariants = builder.coordinateInvariants(type, joint->second.geometry);
  } catch (const std::invalid_argument& e) {
    in.fail(e.what());
  }
  spec.stiffness = in.nonNegative("stiffness", 0.0);
  spec.rest = in.number("rest", joint->second.coordinate) - joint->second.coordinate;
  spec.cubicStiffness = in.nonNegative("cubic_stiffness", 0.0);
  if (spec.revolute && spec.cubicStiffness > 0.0) in.fail("cubic_stiffness applies to prismatic and spherical joints");
  const bool branch = in.has("branch_stiffness");
  if (branch) {
    spec.branchStiffness = in.positive("branch_stiffness");
    spec.viscosity = in.positive("viscosity");
  }
  spec.damping = in.nonNegative("damping", 0.0);
  spec.friction = in.nonNegative("friction", 0.0);
  spec.frictionVelocity = in.positive("friction_velocity", 1e-2);
  if (in.has("heat_node")) {
    const ThermalNodeRef node = thermalNode(in, "heat_node");
    if (node.thermalDof < 0) in.fail("heat_node must have a heat capacity (not a fixed temperature)");
    spec.heatDof = node.thermalDof;
  }
  // a revolute or prismatic coordinate is one element; a spherical bushing one per axis
  std::vector<std::vector<QuadraticForm>> coordinates;
  if (type == JointType::Spherical)
    for (const QuadraticForm& axis : invariants) coordinates.push_back({axis});
  else
    coordinates.push_back(invariants);
  for (std::size_t k = 0; k < coordinates.size(); ++k) {
    JointForceSpec element = spec;
    if (coordinates.size() > 1) element.name += std::string(".") + "xyz"[k];
    element.invariants = coordinates[k];
    if (branch) {
      element.internalDof = layout_.dof(Block::Internal, internalCount_++);
      scale_[element.internalDof] = 1.0;
    }
    components_.push_back(std::make_unique<JointForce>(std::move(element)));
  }
}

}  // namespace mpx
