#include "models/lumped/actuator.hpp"

namespace mpx {

Actuator::Actuator(std::string name, const Endpoint& a, const Endpoint& b, double force, TimeFunction profile)
    : Component(std::move(name), TwoPointGeometry(a, b).dofs()),
      geometry_(a, b),
      force_(force),
      profile_(std::move(profile)) {}

void Actuator::measure(const double*, Measures&) const {}

void Actuator::eemLocal(const StepArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  const Vec3 d0 = geometry_.separation(args.zOld), d1 = geometry_.separation(args.zNew);
  const double length0 = d0.norm(), length1 = d1.norm();
  const double force = force_ * profile_(args.t + 0.5 * args.dt);
  const Vec3 direction = (d0 + d1) / (length0 + length1);  // 2 d_mid / (lambda + lambda')
  geometry_.addForce(out, -force * direction);
  flows.externalWork += force * (length1 - length0) / args.dt;

  const Eigen::Matrix3d dDirection =
      (Eigen::Matrix3d::Identity() - direction * (d1 / length1).transpose()) / (length0 + length1);
  geometry_.addSeparationTangent(out, -force * dDirection);
}

void Actuator::rateLocal(const RateArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  // the power from the velocities, as the damper's rate (docs/theory.md section 6.2)
  const Vec3 d = geometry_.separation(args.z);
  const double length = d.norm();
  const Vec3 unit = d / length;
  const double force = force_ * profile_(args.t);
  geometry_.addForce(out, -force * unit);
  flows.externalWork += force * unit.dot(geometry_.separationVelocity(args.z));
  geometry_.addSeparationTangent(
      out, (-args.alpha * force / length) * (Eigen::Matrix3d::Identity() - unit * unit.transpose()));
}

}  // namespace mpx
