#include "models/fe/solid_inertia.hpp"

namespace mpx {

namespace {
std::vector<int> collectDofs(const SolidInertiaSpec& spec) {
  std::vector<int> dofs;
  for (int shift : {0, spec.velocityShift})
    for (int first : spec.positionDofs)
      for (int k = 0; k < 3; ++k) dofs.push_back(first + shift + k);
  return dofs;
}
}  // namespace

SolidInertia::SolidInertia(const SolidInertiaSpec& spec)
    : Component(spec.name, collectDofs(spec)),
      firstDofs_(spec.positionDofs),
      velocityShift_(spec.velocityShift),
      nodes_(static_cast<int>(spec.positionDofs.size())),
      ownsNode_(spec.ownsNode),
      mass_(Eigen::Matrix<double, kMaxCellNodes, kMaxCellNodes>::Zero()) {
  for (const CellPoint& p : spec.points) mass_ += spec.density * p.weight * p.values * p.values.transpose();
  weight_ = spec.gravity * mass_.rowwise().sum().transpose();
}

void SolidInertia::spatialVectors(std::vector<SpatialVector>& out) const {
  for (int a = 0; a < nodes_; ++a)
    if (ownsNode_[a]) out.push_back({firstDofs_[a], firstDofs_[a] + velocityShift_, SpatialVector::Kind::Point});
}

bool SolidInertia::couples(int row, int column, LocalForm) const {
  const int velocities = 3 * nodes_;
  if (row < velocities) return ownsNode_[row / 3] && (column == row || column == row + velocities);
  // momentum row of component i couples to component i of every node's velocity
  return column >= velocities && column % 3 == row % 3;
}

SolidInertia::NodeVectors SolidInertia::gather(const double* z, int shift) const {
  NodeVectors v = NodeVectors::Zero();
  for (int a = 0; a < nodes_; ++a) v.col(a) = Eigen::Map<const Vec3>(z + firstDofs_[a] + shift);
  return v;
}

void SolidInertia::measure(const double* z, Measures& out) const {
  const NodeVectors x = gather(z, 0), v = gather(z, velocityShift_);
  const NodeVectors momentum = v * mass_;  // column a: sum_b M_ab v_b
  for (int a = 0; a < nodes_; ++a) {
    out.energy += 0.5 * v.col(a).dot(momentum.col(a)) - weight_.col(a).dot(x.col(a));
    out.momentum += momentum.col(a);
    out.angularMomentum += x.col(a).cross(momentum.col(a));
  }
}

void SolidInertia::addRows(const NodeVectors& rate, double rateCoefficient, const NodeVectors& kinematics,
                           double positionCoefficient, double velocityCoefficient, bool tangent,
                           LocalSystem& out) const {
  auto r = out.residual();
  auto K = out.tangent();
  const int velocities = 3 * nodes_;
  const NodeVectors momentumRate = rate * mass_ - weight_;
  for (int a = 0; a < nodes_; ++a) {
    r.segment<3>(velocities + 3 * a) = momentumRate.col(a);
    if (ownsNode_[a]) r.segment<3>(3 * a) = kinematics.col(a);
  }
  if (!tangent) return;
  for (int a = 0; a < nodes_; ++a) {
    for (int b = 0; b < nodes_; ++b)
      K.block<3, 3>(velocities + 3 * a, velocities + 3 * b).diagonal().setConstant(rateCoefficient * mass_(a, b));
    if (!ownsNode_[a]) continue;
    K.block<3, 3>(3 * a, 3 * a).diagonal().setConstant(positionCoefficient);
    K.block<3, 3>(3 * a, velocities + 3 * a).diagonal().setConstant(velocityCoefficient);
  }
}

void SolidInertia::eemLocal(const StepArgs& args, Workspace&, LocalSystem& out, Flows&) const {
  const NodeVectors x0 = gather(args.zOld, 0), x1 = gather(args.zNew, 0);
  const NodeVectors v0 = gather(args.zOld, velocityShift_), v1 = gather(args.zNew, velocityShift_);
  addRows((v1 - v0) / args.dt, 1.0 / args.dt, (x1 - x0) / args.dt - 0.5 * (v0 + v1), 1.0 / args.dt, -0.5, args.tangent,
          out);
}

void SolidInertia::rateLocal(const RateArgs& args, Workspace&, LocalSystem& out, Flows&) const {
  const NodeVectors v = gather(args.z, velocityShift_);
  addRows(gather(args.zdot, velocityShift_), args.beta, gather(args.zdot, 0) - v, args.beta, -args.alpha,
          args.alpha != 0.0 || args.beta != 0.0, out);
}

}  // namespace mpx
