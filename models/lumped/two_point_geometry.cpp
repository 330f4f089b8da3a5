#include "models/lumped/two_point_geometry.hpp"

namespace mpx {

namespace {
// Append a mass point's position and velocity dofs.
void appendMassDofs(const Endpoint& end, std::vector<int>& dofs) {
  if (!end.isMass()) return;
  for (int k = 0; k < 3; ++k) dofs.push_back(end.positionDof + k);
  for (int k = 0; k < 3; ++k) dofs.push_back(end.velocityDof + k);
}

Vec3 pointIn(const Endpoint& end, const double* z) {
  return end.isMass() ? Vec3(z[end.positionDof], z[end.positionDof + 1], z[end.positionDof + 2]) : end.anchor;
}

Vec3 rateIn(const Endpoint& end, const double* zdot) {
  return end.isMass() ? Vec3(zdot[end.positionDof], zdot[end.positionDof + 1], zdot[end.positionDof + 2])
                      : Vec3::Zero();
}
}  // namespace

TwoPointGeometry::TwoPointGeometry(const Endpoint& a, const Endpoint& b) : a_(a), b_(b) {
  int next = 0;
  if (a_.isMass()) {
    localPositionA_ = next;
    localVelocityA_ = next + 3;
    next += 6;
  }
  if (b_.isMass()) {
    localPositionB_ = next;
    localVelocityB_ = next + 3;
  }
}

std::vector<int> TwoPointGeometry::dofs() const {
  std::vector<int> dofs;
  appendMassDofs(a_, dofs);
  appendMassDofs(b_, dofs);
  return dofs;
}

Vec3 TwoPointGeometry::separation(const double* z) const { return pointIn(b_, z) - pointIn(a_, z); }

Vec3 TwoPointGeometry::separationRate(const double* zdot) const { return rateIn(b_, zdot) - rateIn(a_, zdot); }

Vec3 TwoPointGeometry::separationVelocity(const double* z) const {
  auto velocity = [z](const Endpoint& end) {
    return end.isMass() ? Vec3(z[end.velocityDof], z[end.velocityDof + 1], z[end.velocityDof + 2]) : Vec3::Zero();
  };
  return velocity(b_) - velocity(a_);
}

void TwoPointGeometry::addForce(LocalSystem& local, const Vec3& force) const {
  auto r = local.residual();
  if (localVelocityB_ >= 0) r.segment<3>(localVelocityB_) += force;
  if (localVelocityA_ >= 0) r.segment<3>(localVelocityA_) -= force;
}

void TwoPointGeometry::addForceTangent(LocalSystem& local, const Vec3& direction, const LocalRow& dForce) const {
  auto K = local.tangent();
  if (localVelocityB_ >= 0) K.middleRows(localVelocityB_, 3) += direction * dForce;
  if (localVelocityA_ >= 0) K.middleRows(localVelocityA_, 3) -= direction * dForce;
}

void TwoPointGeometry::addSeparationTangent(LocalSystem& local, const Eigen::Matrix3d& dForceDd) const {
  addMomentumTangent(local, dForceDd, localPositionB_, localPositionA_);
}

void TwoPointGeometry::addSeparationVelocityTangent(LocalSystem& local, const Eigen::Matrix3d& dForceDw) const {
  addMomentumTangent(local, dForceDw, localVelocityB_, localVelocityA_);
}

void TwoPointGeometry::addMomentumTangent(LocalSystem& local, const Eigen::Matrix3d& dForce, int columnB,
                                          int columnA) const {
  auto K = local.tangent();
  const int rows[2] = {localVelocityB_, localVelocityA_};
  const int cols[2] = {columnB, columnA};
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      if (rows[i] >= 0 && cols[j] >= 0) K.block<3, 3>(rows[i], cols[j]) += (i == j ? 1.0 : -1.0) * dForce;
}

void TwoPointGeometry::addSeparationRow(LocalRow& row, const Vec3& w) const {
  if (localPositionB_ >= 0) row.segment<3>(localPositionB_) += w.transpose();
  if (localPositionA_ >= 0) row.segment<3>(localPositionA_) -= w.transpose();
}

}  // namespace mpx
