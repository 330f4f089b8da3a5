// Rigid bodies, joints, joint force elements and torques (docs/scene-format.md).
#include "models/multibody/external_torque.hpp"
#include "models/multibody/inertia.hpp"
#include "models/multibody/joint_force.hpp"
#include "models/scene/scene_build.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>

#include <cmath>

namespace mpx {

namespace {

// The six director constraints d_i . d_j = delta_ij of a body.
constexpr int kRigidityConstraints = 6;

DofDemand declareBody(ElementReader& in, SceneBuild& build) {
  return {12, 0, 0, build.takesMultipliers(in) ? 2 * kRigidityConstraints : 0};
}

void buildBody(ElementReader& in, SceneBuild& build, DofRange& dofs) {
  const std::string name = build.declareName(in);
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
  const ConstraintSettings rigidity = build.constraintSettings(in);

  // principal axes of the inertia tensor (given in the body frame) become the directors
  const Mat3 rotation = orientation.toRotationMatrix();
  const Eigen::SelfAdjointEigenSolver<Mat3> principal(rotation * tensor * rotation.transpose());
  const Vec3 J = principal.eigenvalues();
  Mat3 directors = principal.eigenvectors();
  if (directors.determinant() < 0) directors.col(2) *= -1.0;
  if (!(J.minCoeff() > 0.0)) in.fail("the inertia tensor must be positive definite");
  const Vec3 E(0.5 * (J[1] + J[2] - J[0]), 0.5 * (J[2] + J[0] - J[1]), 0.5 * (J[0] + J[1] - J[2]));
  if (!(E.minCoeff() > 0.0))
    in.fail(
        "principal moments must satisfy the strict triangle inequality J_i < J_j + J_k "
        "(the director mass matrix needs (J_j + J_k - J_i)/2 > 0)");

  const int phi = dofs.take(Block::Position, 12), phiRate = phi + build.velocityShift();
  build.state.segment<3>(phi) = position;
  build.state.segment<3>(phiRate) = velocity;
  for (int i = 0; i < 3; ++i) {
    build.state.segment<3>(phi + 3 + 3 * i) = directors.col(i);
    build.state.segment<3>(phiRate + 3 + 3 * i) = angularVelocity.cross(directors.col(i));
  }
  build.keepPositionScale(position.norm());
  build.points[name] = Endpoint::point(phi, phiRate);
  build.attachments[name] = Attachment{Attachment::Kind::Body, phi, position, directors};
  build.bodyFrames.push_back({name, phi, directors.transpose() * rotation});
  build.addComponent(std::make_unique<Inertia>(
      name, phi, phiRate, std::vector<InertiaBlock>{{mass, true}, {E[0], false}, {E[1], false}, {E[2], false}},
      build.spec.gravity));
  const JointBuilder builder(build.attachments[name]);
  build.addConstraint(name + ".rigidity", builder, builder.rigidity(), /*leadingGap=*/false, rigidity, dofs);
}

DofDemand declareJoint(ElementReader& in, SceneBuild& build) {
  const std::string* type = in.element().find("type");
  const std::optional<JointType> joint = type ? jointTypeByName(*type) : std::nullopt;
  if (!joint) return {};  // reported when the joint is built
  if (const std::string* name = in.element().find("name")) build.jointTypes.emplace(*name, *joint);
  return {0, 0, 0, build.takesMultipliers(in) ? 2 * constraintCount(*joint) : 0};
}

void buildJoint(ElementReader& in, SceneBuild& build, DofRange& dofs) {
  const std::string name = build.declareName(in);
  const std::string typeName = in.text("type");
  const std::optional<JointType> type = jointTypeByName(typeName);
  if (!type) in.fail("unknown joint type '" + typeName + "' (choose " + kJointTypeNames + ")");
  const Attachment a = build.attachment(in, "a"), b = build.attachment(in, "b");
  // an attribute another joint type reads is an error here, not silently ignored
  const bool revoluteOrPrismatic = *type == JointType::Revolute || *type == JointType::Prismatic;
  const bool axial = revoluteOrPrismatic || *type == JointType::Universal || *type == JointType::Cylindrical ||
                     *type == JointType::Planar;
  auto onlyFor = [&](const char* attribute, bool applies, const char* types) {
    if (!applies && in.has(attribute))
      in.fail(std::string("attribute '") + attribute + "' applies to " + types + " joints only, not " + typeName);
  };
  onlyFor("axis", axial, "revolute, universal, cylindrical, prismatic and planar");
  onlyFor("axis_b", *type == JointType::Universal, "universal");
  onlyFor("anchor_b", *type == JointType::Distance, "distance");
  onlyFor("coordinate", revoluteOrPrismatic, "revolute and prismatic");
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
  // degenerate geometry would otherwise surface as a singular tangent at the first step
  if (*in.element().find("a") == *in.element().find("b")) in.fail("a joint needs two different ends, a and b");
  if (*type == JointType::Universal && !(std::abs(geometry.axis.dot(geometry.axisB)) <= 1e-6))
    in.fail(fmt::format("a universal joint needs axis_b perpendicular to axis (the cosine between them is {:.3g})",
                        geometry.axis.dot(geometry.axisB)));
  const double coordinate = in.number("coordinate", 0.0);
  const ConstraintSettings settings = build.constraintSettings(in);
  const JointBuilder builder(a, b);
  try {
    build.addConstraint(name, builder, builder.joint(*type, geometry), coincidesPoints(*type), settings, dofs);
  } catch (const std::invalid_argument& e) {
    in.fail(e.what());
  }
  build.joints[name] = DeclaredJoint{*type, a, b, geometry, coordinate};
  if (*type == JointType::Revolute || *type == JointType::Prismatic)
    build.jointCoordinates.emplace_back(name, *type == JointType::Revolute, builder.positionDofs(),
                                        build.velocityShift(), builder.coordinateInvariants(*type, geometry),
                                        coordinate);
}

// A Maxwell branch takes one internal variable per coordinate: three on a spherical bushing.
DofDemand declareJointForce(ElementReader& in, SceneBuild& build) {
  if (!in.has("branch_stiffness")) return {};
  const std::string* joint = in.element().find("joint");
  const auto type = joint ? build.jointTypes.find(*joint) : build.jointTypes.end();
  const bool spherical = type != build.jointTypes.end() && type->second == JointType::Spherical;
  return {0, 0, spherical ? 3 : 1, 0};
}

// lower, upper (the joint's convention, as rest), limit_stiffness and limit_damping of a joint force.
JointStop readJointStop(ElementReader& in, const DeclaredJoint& joint) {
  if (joint.type == JointType::Spherical) in.fail("lower and upper apply to revolute and prismatic joints");
  JointStop stop;
  stop.lower = in.number("lower") - joint.coordinate;
  stop.upper = in.number("upper") - joint.coordinate;
  if (!(stop.lower < stop.upper)) in.fail("lower must be below upper");
  // a revolute stop's chart is centred on the middle of the range
  if (joint.type == JointType::Revolute && !(stop.upper - stop.lower < 2.0 * M_PI))
    in.fail("the range of a revolute joint's stops must be below a full turn (2 pi)");
  stop.stiffness = in.positive("limit_stiffness");
  stop.damping = in.nonNegative("limit_damping", 0.0);
  return stop;
}

void buildJointForce(ElementReader& in, SceneBuild& build, DofRange& dofs) {
  JointForceSpec spec;
  spec.name = build.declareName(in);
  const std::string jointName = in.text("joint");
  const auto joint = build.joints.find(jointName);
  if (joint == build.joints.end()) in.fail("attribute 'joint': no joint named '" + jointName + "' declared above");
  const JointType type = joint->second.type;
  if (type != JointType::Revolute && type != JointType::Prismatic && type != JointType::Spherical)
    in.fail("joint '" + jointName + "' is not revolute, prismatic or spherical: joint forces act on those");
  const JointBuilder builder(joint->second.a, joint->second.b);
  spec.revolute = type == JointType::Revolute;
  spec.positionDofs = builder.positionDofs();
  spec.velocityShift = build.velocityShift();
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
  if (in.has("lower") || in.has("upper")) spec.stop = readJointStop(in, joint->second);
  spec.damping = in.nonNegative("damping", 0.0);
  spec.friction = in.nonNegative("friction", 0.0);
  spec.frictionVelocity = in.positive("friction_velocity", 1e-2);
  if (in.has("friction_velocity") && !(spec.friction > 0.0)) in.fail("friction_velocity needs friction > 0");
  if (in.has("heat_node")) {
    const ThermalNodeRef node = build.thermalNode(in, "heat_node");
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
      element.internalDof = dofs.take(Block::Internal, 1);
      build.scale[element.internalDof] = 1.0;
    }
    build.addComponent(std::make_unique<JointForce>(std::move(element)));
  }
}

void buildTorque(ElementReader& in, SceneBuild& build, DofRange&) {
  const std::string name = build.declareName(in);
  const std::string target = in.text("on");
  const auto body = build.attachments.find(target);
  if (body == build.attachments.end() || body->second.kind != Attachment::Kind::Body)
    in.fail("attribute 'on': no body named '" + target + "' declared above this element");
  const Vec3 torque = in.vector("torque", Vec3::Zero());
  build.addComponent(std::make_unique<ExternalTorque>(name, body->second.firstPositionDof + 3, build.velocityShift(),
                                                      torque, readProfile(in, build)));
}

}  // namespace

const std::vector<ElementKind>& multibodyElementKinds() {
  static const std::vector<ElementKind> kinds = {
      {"body", declareBody, buildBody},
      {"joint", declareJoint, buildJoint},
      {"joint_force", declareJointForce, buildJointForce},
      {"torque", nullptr, buildTorque},
  };
  return kinds;
}

}  // namespace mpx
