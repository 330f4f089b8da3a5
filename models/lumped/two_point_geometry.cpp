#include "models/lumped/two_point_geometry.hpp"

namespace mpx {

namespace {
// sum_k weights[k] y_k with y_k the k-th 3-vector from `first` in v.
Vec3 combination(const Endpoint& end, const double* v, int first) {
  Vec3 x = Vec3::Zero();
  for (int k = 0; k < end.terms; ++k)
    x += end.weights[k] * Vec3(v[first + 3 * k], v[first + 3 * k + 1], v[first + 3 * k + 2]);
  return x;
}
}  // namespace

Endpoint Endpoint::fixed(const Vec3& position) {
  Endpoint end;
  end.anchor = position;
  return end;
}

Endpoint Endpoint::point(int positionDof, int velocityDof) {
  Endpoint end;
  end.positionDof = positionDof;
  end.velocityDof = velocityDof;
  end.terms = 1;
  end.weights[0] = 1.0;
  return end;
}

Endpoint Endpoint::bodyPoint(int positionDof, int velocityDof, const Vec3& bodyCoordinates) {
  Endpoint end = point(positionDof, velocityDof);
  end.terms = 4;
  for (int i = 0; i < 3; ++i) end.weights[1 + i] = bodyCoordinates[i];
  return end;
}

Vec3 Endpoint::in(const double* z) const { return moves() ? combination(*this, z, positionDof) : anchor; }

TwoPointGeometry::TwoPointGeometry(const Endpoint& a, const Endpoint& b) {
  ends_[0].point = b;
  ends_[1].point = a;
  ends_[1].sign = -1.0;
  // a's dofs come first locally
  int next = 0;
  for (int e : {1, 0}) {
    End& end = ends_[e];
    if (!end.point.moves()) continue;
    end.localPosition = next;
    end.localVelocity = next + 3 * end.point.terms;
    next += 6 * end.point.terms;
  }
}

std::vector<int> TwoPointGeometry::dofs() const {
  std::vector<int> dofs;
  for (int e : {1, 0}) {
    const Endpoint& end = ends_[e].point;
    for (int i = 0; i < 3 * end.terms; ++i) dofs.push_back(end.positionDof + i);
    for (int i = 0; i < 3 * end.terms; ++i) dofs.push_back(end.velocityDof + i);
  }
  return dofs;
}

Vec3 TwoPointGeometry::separation(const double* z) const { return ends_[0].point.in(z)-ends_[1].point.in(z); }

Vec3 TwoPointGeometry::separationRate(const double* zdot) const {
  return combination(ends_[0].point, zdot, ends_[0].point.positionDof) -
         combination(ends_[1].point, zdot, ends_[1].point.positionDof);
}

Vec3 TwoPointGeometry::separationVelocity(const double* z) const {
  return combination(ends_[0].point, z, ends_[0].point.velocityDof) -
         combination(ends_[1].point, z, ends_[1].point.velocityDof);
}

// The force on an end point enters its momentum rows through the transpose of its map:
// weights[k] * force on the rows of y_k.
void TwoPointGeometry::addForce(LocalSystem& local, const Vec3& force) const {
  auto r = local.residual();
  for (const End& end : ends_)
    for (int k = 0; k < end.point.terms; ++k)
      r.segment<3>(end.localVelocity + 3 * k) += (end.sign * end.point.weights[k]) * force;
}

void TwoPointGeometry::addForceTangent(LocalSystem& local, const Vec3& direction, const LocalRow& dForce) const {
  auto K = local.tangent();
  for (const End& end : ends_)
    for (int k = 0; k < end.point.terms; ++k)
      K.middleRows(end.localVelocity + 3 * k, 3).noalias() += ((end.sign * end.point.weights[k]) * direction) * dForce;
}

void TwoPointGeometry::addSeparationTangent(LocalSystem& local, const Eigen::Matrix3d& dForceDd) const {
  addMomentumTangent(local, dForceDd, false);
}

void TwoPointGeometry::addSeparationVelocityTangent(LocalSystem& local, const Eigen::Matrix3d& dForceDw) const {
  addMomentumTangent(local, dForceDw, true);
}

void TwoPointGeometry::addMomentumTangent(LocalSystem& local, const Eigen::Matrix3d& dForce,
                                          bool velocityColumns) const {
  auto K = local.tangent();
  for (const End& row : ends_)
    for (const End& column : ends_) {
      const int firstColumn = velocityColumns ? column.localVelocity : column.localPosition;
      for (int k = 0; k < row.point.terms; ++k)
        for (int l = 0; l < column.point.terms; ++l)
          K.block<3, 3>(row.localVelocity + 3 * k, firstColumn + 3 * l) +=
              (row.sign * column.sign * row.point.weights[k] * column.point.weights[l]) * dForce;
    }
}

void TwoPointGeometry::addSeparationRow(LocalRow& row, const Vec3& w) const {
  for (const End& end : ends_)
    for (int k = 0; k < end.point.terms; ++k)
      row.segment<3>(end.localPosition + 3 * k) += (end.sign * end.point.weights[k]) * w.transpose();
}

bool TwoPointGeometry::inEndBlock(int local, int End::*first) const {
  for (const End& end : ends_)
    if (end.point.moves() && local >= end.*first && local < end.*first + 3 * end.point.terms) return true;
  return false;
}

bool TwoPointGeometry::isPosition(int local) const { return inEndBlock(local, &End::localPosition); }

bool TwoPointGeometry::isVelocity(int local) const { return inEndBlock(local, &End::localVelocity); }

}  // namespace mpx
