#include "point_mass.hpp"

namespace mpx {

namespace {
std::vector<int> massDofs(int positionDof, int velocityDof) {
  return {positionDof, positionDof + 1, positionDof + 2, velocityDof, velocityDof + 1, velocityDof + 2};
}
Vec3 vec3At(const double* z, int dof) { return {z[dof], z[dof + 1], z[dof + 2]}; }
}  // namespace

PointMass::PointMass(std::string name, double mass, int positionDof, int velocityDof, const Vec3& gravity)
    : Component(std::move(name), massDofs(positionDof, velocityDof)),
      mass_(mass),
      positionDof_(positionDof),
      velocityDof_(velocityDof),
      gravity_(gravity) {}

void PointMass::measure(const double* z, Measures& out) const {
  const Vec3 x = vec3At(z, positionDof_), v = vec3At(z, velocityDof_);
  out.energy += 0.5 * mass_ * v.squaredNorm() - mass_ * gravity_.dot(x);
  out.momentum += mass_ * v;
  out.angularMomentum += x.cross(mass_ * v);
}

void PointMass::eemLocal(const StepArgs& args, Workspace&, LocalSystem& out, Flows&) const {
  const Vec3 x0 = vec3At(args.zOld, positionDof_), x1 = vec3At(args.zNew, positionDof_);
  const Vec3 v0 = vec3At(args.zOld, velocityDof_), v1 = vec3At(args.zNew, velocityDof_);
  auto r = out.residual();
  auto K = out.tangent();
  // kinematics (x' - x)/dt = v_mid; momentum m (v' - v)/dt = m g (the gravity work is exact)
  r.head<3>() = (x1 - x0) / args.dt - 0.5 * (v0 + v1);
  r.tail<3>() = mass_ * (v1 - v0) / args.dt - mass_ * gravity_;
  K.block<3, 3>(0, 0).diagonal().setConstant(1.0 / args.dt);
  K.block<3, 3>(0, 3).diagonal().setConstant(-0.5);
  K.block<3, 3>(3, 3).diagonal().setConstant(mass_ / args.dt);
}

void PointMass::rateLocal(const RateArgs& args, Workspace&, LocalSystem& out, Flows&) const {
  auto r = out.residual();
  auto K = out.tangent();
  r.head<3>() = vec3At(args.zdot, positionDof_) - vec3At(args.z, velocityDof_);
  r.tail<3>() = mass_ * vec3At(args.zdot, velocityDof_) - mass_ * gravity_;
  K.block<3, 3>(0, 0).diagonal().setConstant(args.beta);
  K.block<3, 3>(0, 3).diagonal().setConstant(-args.alpha);
  K.block<3, 3>(3, 3).diagonal().setConstant(args.beta * mass_);
}

}  // namespace mpx
