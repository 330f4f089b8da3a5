#include "models/multibody/inertia.hpp"

namespace mpx {

namespace {
std::vector<int> inertiaDofs(int firstPositionDof, int firstVelocityDof, std::size_t blocks) {
  std::vector<int> dofs;
  for (std::size_t i = 0; i < 3 * blocks; ++i) dofs.push_back(firstPositionDof + static_cast<int>(i));
  for (std::size_t i = 0; i < 3 * blocks; ++i) dofs.push_back(firstVelocityDof + static_cast<int>(i));
  return dofs;
}
Vec3 vec3At(const double* z, int dof) { return {z[dof], z[dof + 1], z[dof + 2]}; }
}  // namespace

Inertia::Inertia(std::string name, int firstPositionDof, int firstVelocityDof, std::vector<InertiaBlock> blocks,
                 const Vec3& gravity)
    : Component(std::move(name), inertiaDofs(firstPositionDof, firstVelocityDof, blocks.size())),
      firstPositionDof_(firstPositionDof),
      firstVelocityDof_(firstVelocityDof),
      blocks_(std::move(blocks)),
      gravity_(gravity) {}

void Inertia::spatialVectors(std::vector<SpatialVector>& out) const {
  for (std::size_t b = 0; b < blocks_.size(); ++b)
    out.push_back({firstPositionDof_ + 3 * static_cast<int>(b), firstVelocityDof_ + 3 * static_cast<int>(b),
                   blocks_[b].translational ? SpatialVector::Kind::Point : SpatialVector::Kind::Direction});
}

void Inertia::measure(const double* z, Measures& out) const {
  for (std::size_t b = 0; b < blocks_.size(); ++b) {
    const Vec3 x = vec3At(z, firstPositionDof_ + 3 * b), v = vec3At(z, firstVelocityDof_ + 3 * b);
    const double m = blocks_[b].mass;
    out.energy += 0.5 * m * v.squaredNorm() - weight(b).dot(x);
    if (blocks_[b].translational) out.momentum += m * v;
    out.angularMomentum += x.cross(m * v);  // d_i x E_i d_i' for a director block
  }
}

void Inertia::eemLocal(const StepArgs& args, Workspace&, LocalSystem& out, Flows&) const {
  auto r = out.residual();
  auto K = out.tangent();
  const int velocityRows = 3 * static_cast<int>(blocks_.size());
  for (std::size_t b = 0; b < blocks_.size(); ++b) {
    const int p = 3 * static_cast<int>(b), v = velocityRows + p;
    const Vec3 x0 = vec3At(args.zOld, firstPositionDof_ + p), x1 = vec3At(args.zNew, firstPositionDof_ + p);
    const Vec3 v0 = vec3At(args.zOld, firstVelocityDof_ + p), v1 = vec3At(args.zNew, firstVelocityDof_ + p);
    const double m = blocks_[b].mass;
    // kinematics (x' - x)/dt = v_mid; momentum m (v' - v)/dt = m g (the gravity work is exact)
    r.segment<3>(p) = (x1 - x0) / args.dt - 0.5 * (v0 + v1);
    r.segment<3>(v) = m * (v1 - v0) / args.dt - weight(b);
    K.block<3, 3>(p, p).diagonal().setConstant(1.0 / args.dt);
    K.block<3, 3>(p, v).diagonal().setConstant(-0.5);
    K.block<3, 3>(v, v).diagonal().setConstant(m / args.dt);
  }
}

void Inertia::rateLocal(const RateArgs& args, Workspace&, LocalSystem& out, Flows&) const {
  auto r = out.residual();
  auto K = out.tangent();
  const int velocityRows = 3 * static_cast<int>(blocks_.size());
  for (std::size_t b = 0; b < blocks_.size(); ++b) {
    const int p = 3 * static_cast<int>(b), v = velocityRows + p;
    const double m = blocks_[b].mass;
    r.segment<3>(p) = vec3At(args.zdot, firstPositionDof_ + p) - vec3At(args.z, firstVelocityDof_ + p);
    r.segment<3>(v) = m * vec3At(args.zdot, firstVelocityDof_ + p) - weight(b);
    K.block<3, 3>(p, p).diagonal().setConstant(args.beta);
    K.block<3, 3>(p, v).diagonal().setConstant(-args.alpha);
    K.block<3, 3>(v, v).diagonal().setConstant(args.beta * m);
  }
}

}  // namespace mpx
