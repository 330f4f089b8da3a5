#include "models/fe/material.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace mpx {

namespace {

// The isotropic quadratic energy lambda/2 tr(A)^2 + mu A:A of a strain A, shared by St Venant-Kirchhoff and the
// Maxwell branch.
double quadraticEnergy(const LameParameters& lame, const Mat3& A) {
  const double trace = A.trace();
  return 0.5 * lame.lambda * trace * trace + lame.mu * A.squaredNorm();
}

// Its derivative with respect to A, lambda tr(A) I + 2 mu A (linear, so also its increment).
Mat3 quadraticStress(const LameParameters& lame, const Mat3& A) {
  return lame.lambda * A.trace() * Mat3::Identity() + 2.0 * lame.mu * A;
}

// ln J = ln(det C)/2; NaN when det C <= 0, which then propagates through every Neo-Hooke quantity.
double logJacobian(const Mat3& C) {
  const double det = C.determinant();
  return det > 0.0 ? 0.5 * std::log(det) : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

LameParameters LameParameters::fromYoung(double young, double poisson) {
  // negated comparisons also reject NaN
  if (!(young > 0.0)) throw std::invalid_argument("Young's modulus must be positive, got " + std::to_string(young));
  if (!(poisson > -1.0 && poisson < 0.5))
    throw std::invalid_argument("Poisson's ratio must lie in (-1, 0.5), got " + std::to_string(poisson));
  return {young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson)), young / (2.0 * (1.0 + poisson))};
}

SaintVenantKirchhoff::SaintVenantKirchhoff(LameParameters lame) : lame_(lame) {}

double SaintVenantKirchhoff::energy(const Mat3& C) const { return quadraticEnergy(lame_, greenStrain(C)); }

// S = 2 dW/dC = dW/dE since dE = dC/2
Mat3 SaintVenantKirchhoff::stress(const Mat3& C) const { return quadraticStress(lame_, greenStrain(C)); }

Mat3 SaintVenantKirchhoff::stressIncrement(const Mat3&, const Mat3& dC) const {
  return quadraticStress(lame_, 0.5 * dC);
}

// With dE = dC/2 and A = E1 + E0 = 2 E0 + dE: lambda/2 tr(dE) tr(A) + mu dE:A.
double SaintVenantKirchhoff::energyDifference(const Mat3& C0, const Mat3& dC) const {
  const Mat3 strainDifference = 0.5 * dC, strainSum = 2.0 * greenStrain(C0) + strainDifference;
  return 0.5 * lame_.lambda * strainDifference.trace() * strainSum.trace() +
         lame_.mu * strainDifference.cwiseProduct(strainSum).sum();
}

NeoHooke::NeoHooke(LameParameters lame) : lame_(lame) {}

namespace {
// Adjugate of a 3 x 3 matrix: rows are cross products of its columns.
Mat3 adjugate(const Mat3& m) {
  Mat3 adj;
  adj.row(0) = m.col(1).cross(m.col(2)).transpose();
  adj.row(1) = m.col(2).cross(m.col(0)).transpose();
  adj.row(2) = m.col(0).cross(m.col(1)).transpose();
  return adj;
}
}  // namespace

// ln J1 - ln J0 = ln(1 + (det C1 - det C0)/det C0)/2, the determinant difference expanded in
// D = C1 - C0: det(C0 + D) - det C0 = tr(adj(C0) D) + tr(C0 adj(D)) + det D.
double logJacobianChange(const Mat3& C0, const Mat3& D) {
  const double det0 = C0.determinant();
  const double detDifference = (adjugate(C0) * D).trace() + (C0 * adjugate(D)).trace() + D.determinant();
  if (!(det0 > 0.0) || !(det0 + detDifference > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return 0.5 * std::log1p(detDifference / det0);
}

double NeoHooke::energyDifference(const Mat3& C0, const Mat3& D) const {
  const double logJ0 = logJacobian(C0), logJChange = logJacobianChange(C0, D);
  return 0.5 * lame_.mu * D.trace() - lame_.mu * logJChange +
         0.5 * lame_.lambda * logJChange * (2.0 * logJ0 + logJChange);
}

double NeoHooke::energy(const Mat3& C) const {
  const double logJ = logJacobian(C);
  return 0.5 * lame_.mu * (C.trace() - 3.0) - lame_.mu * logJ + 0.5 * lame_.lambda * logJ * logJ;
}

// S = mu I + (lambda ln J - mu) C^-1, from d(ln J)/dC = C^-1/2
Mat3 NeoHooke::stress(const Mat3& C) const {
  const double logJ = logJacobian(C);
  return lame_.mu * Mat3::Identity() + (lame_.lambda * logJ - lame_.mu) * C.inverse();
}

// dS[dC] = lambda/2 (C^-1:dC) C^-1 + (mu - lambda ln J) C^-1 dC C^-1, from d(C^-1)[dC] = -C^-1 dC C^-1
Mat3 NeoHooke::stressIncrement(const Mat3& C, const Mat3& dC) const {
  const double logJ = logJacobian(C);
  const Mat3 inverse = C.inverse();
  return 0.5 * lame_.lambda * inverse.cwiseProduct(dC).sum() * inverse +
         (lame_.mu - lame_.lambda * logJ) * inverse * dC * inverse;
}

VolumeLogarithm::VolumeLogarithm(double coefficient) : coefficient_(coefficient) {}

double VolumeLogarithm::energy(const Mat3& C) const { return coefficient_ * logJacobian(C); }

// 2 d(c ln J)/dC = c C^-1
Mat3 VolumeLogarithm::stress(const Mat3& C) const {
  return C.determinant() > 0.0 ? Mat3(coefficient_ * C.inverse()) : Mat3::Constant(std::nan(""));
}

Mat3 VolumeLogarithm::stressIncrement(const Mat3& C, const Mat3& dC) const {
  const Mat3 inverse = C.inverse();
  return -coefficient_ * inverse * dC * inverse;
}

double VolumeLogarithm::energyDifference(const Mat3& C0, const Mat3& dC) const {
  return coefficient_ * logJacobianChange(C0, dC);
}

double ViscousBranch::energy(const Mat3& C, const Mat3& Gamma) const {
  return quadraticEnergy(moduli, greenStrain(C) - Gamma);
}

Mat3 ViscousBranch::stress(const Mat3& C, const Mat3& Gamma) const {
  return quadraticStress(moduli, greenStrain(C) - Gamma);
}

}  // namespace mpx
