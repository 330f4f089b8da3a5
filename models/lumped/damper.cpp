#include "models/lumped/damper.hpp"

namespace mpx {

Damper::Damper(std::string name, const Endpoint& a, const Endpoint& b, double coefficient)
    : Component(std::move(name), TwoPointGeometry(a, b).dofs()), geometry_(a, b), coefficient_(coefficient) {}

void Damper::measure(const double*, Measures&) const {}

void Damper::eemLocal(const StepArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  const Vec3 d0 = geometry_.separation(args.zOld), d1 = geometry_.separation(args.zNew);
  const double length0 = d0.norm(), length1 = d1.norm();
  const double force = coefficient_ * (length1 - length0) / args.dt;
  const Vec3 direction = (d0 + d1) / (length0 + length1);  // 2 d_mid / (lambda + lambda')
  geometry_.addForce(out, force * direction);
  flows.dissipated += force * (length1 - length0) / args.dt;

  // tangent: both the force and its direction depend on d' = d1
  const Vec3 dLength1 = d1 / length1;
  const Eigen::Matrix3d dDirection =
      (Eigen::Matrix3d::Identity() - direction * dLength1.transpose()) / (length0 + length1);
  geometry_.addSeparationTangent(out, (coefficient_ / args.dt) * direction * dLength1.transpose() + force * dDirection);
}

void Damper::rateLocal(const RateArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  // the length rate from the velocities, not from the position rates: under constraints the
  // GGL kinematic rows make q' = v - mu dPhi/dq, and a stiff damper on q' would amplify the
  // index-2 multiplier mu into the momentum rows (docs/theory.md section 6.2)
  const Vec3 d = geometry_.separation(args.z), dRate = geometry_.separationVelocity(args.z);
  const double length = d.norm();
  const Vec3 unit = d / length;
  const double lengthRate = unit.dot(dRate);
  const double force = coefficient_ * lengthRate;
  geometry_.addForce(out, force * unit);
  flows.dissipated += force * lengthRate;

  // the positions enter through the direction and the length rate, the velocities through the
  // length rate
  const Eigen::Matrix3d dUnit = (Eigen::Matrix3d::Identity() - unit * unit.transpose()) / length;
  const Vec3 dLengthRateDd = dUnit * dRate;
  geometry_.addSeparationTangent(out, args.alpha * (coefficient_ * unit * dLengthRateDd.transpose() + force * dUnit));
  geometry_.addSeparationVelocityTangent(out, args.alpha * coefficient_ * unit * unit.transpose());
}

}  // namespace mpx
