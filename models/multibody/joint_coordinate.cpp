#include "models/multibody/joint_coordinate.hpp"

#include <cmath>

namespace mpx {

Jet jointCoordinateChart(bool revolute, const Vec3& I, const Vec3& centre) {
  Jet jet;
  if (!revolute) {
    jet.value = I[0];
    jet.grad[0] = 1.0;
    return jet;
  }
  // (x, y) = A (u, v) rotates the centre's direction onto the x axis; theta = atan2(y, x)
  Eigen::Matrix2d A;
  A << centre[0], centre[1], -centre[1], centre[0];
  const Eigen::Vector2d xy = A * I.head<2>();
  const double x = xy[0], y = xy[1], rho2 = x * x + y * y, rho4 = rho2 * rho2;
  Eigen::Matrix2d hessXY;
  hessXY << 2.0 * x * y / rho4, (y * y - x * x) / rho4, (y * y - x * x) / rho4, -2.0 * x * y / rho4;
  jet.value = std::atan2(y, x);
  jet.grad.head<2>() = A.transpose() * Eigen::Vector2d(-y / rho2, x / rho2);
  jet.hess.topLeftCorner<2, 2>() = A.transpose() * hessXY * A;
  return jet;
}

JointCoordinate::JointCoordinate(std::string name, bool revolute, std::vector<int> positionDofs, int velocityShift,
                                 std::vector<QuadraticForm> invariants, double offset)
    : name_(std::move(name)),
      revolute_(revolute),
      positionDofs_(std::move(positionDofs)),
      velocityShift_(velocityShift),
      invariants_(std::move(invariants)),
      offset_(offset) {}

ConstraintVector JointCoordinate::gather(const double* z, int shift) const {
  ConstraintVector q(positionDofs_.size());
  for (std::size_t i = 0; i < positionDofs_.size(); ++i) q[i] = z[positionDofs_[i] + shift];
  return q;
}

Vec3 JointCoordinate::invariantsAt(const ConstraintVector& q) const {
  Vec3 I = Vec3::Zero();
  for (std::size_t a = 0; a < invariants_.size(); ++a) I[a] = invariants_[a].valueAt(q);
  return I;
}

double JointCoordinate::position(const double* z, double previous) const {
  const Vec3 I = invariantsAt(gather(z, 0));
  if (!revolute_) return I[0] + offset_;
  // the angle's representative closest to the previous value
  const double angle = std::atan2(I[1], I[0]) + offset_;
  return angle + 2.0 * M_PI * std::round((previous - angle) / (2.0 * M_PI));
}

double JointCoordinate::velocity(const double* z) const {
  const ConstraintVector q = gather(z, 0), v = gather(z, velocityShift_);
  const Vec3 I = invariantsAt(q);
  const Jet chart = jointCoordinateChart(revolute_, I, I);
  double rate = 0.0;
  for (std::size_t a = 0; a < invariants_.size(); ++a) rate += chart.grad[a] * invariants_[a].gradientAt(q).dot(v);
  return rate;
}

}  // namespace mpx
