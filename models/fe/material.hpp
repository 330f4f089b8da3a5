#pragma once
// Pointwise finite-strain material laws, pure functions of the right Cauchy-Green tensor C = F^T F (symmetric
// positive definite) per unit reference volume: hyperelastic laws W(C) with their second Piola-Kirchhoff stress
// S = 2 dW/dC and its directional derivative, and a Maxwell branch in Green strain with a viscous strain Gamma.
#include <Eigen/Dense>

namespace mpx {

using Mat3 = Eigen::Matrix3d;

// Lame constants from Young's modulus and Poisson's ratio; throws std::invalid_argument unless E > 0 and
// -1 < nu < 0.5 (the message says which).
struct LameParameters {
  double lambda, mu;
  static LameParameters fromYoung(double young, double poisson);
};

// A hyperelastic law in terms of the right Cauchy-Green tensor C (symmetric positive definite), per unit reference
// volume.
class HyperelasticMaterial {
 public:
  virtual ~HyperelasticMaterial() = default;
  // W(C)
  virtual double energy(const Mat3& C) const = 0;
  // S = 2 dW/dC (second Piola-Kirchhoff), symmetric
  virtual Mat3 stress(const Mat3& C) const = 0;
  // directional derivative dS(C)[dC] (dC symmetric)
  virtual Mat3 stressIncrement(const Mat3& C, const Mat3& dC) const = 0;
  // W(C1) - W(C0) computed from C1 - C0 without cancellation: its error is round-off of the
  // difference, not of W, which the Gonzalez quotient divides by |C1 - C0|^2.
  virtual double energyDifference(const Mat3& C0, const Mat3& C1) const = 0;
};

// W = lambda/2 (tr E)^2 + mu E:E, E = (C - I)/2
class SaintVenantKirchhoff final : public HyperelasticMaterial {
 public:
  explicit SaintVenantKirchhoff(LameParameters lame);
  double energy(const Mat3& C) const override;
  Mat3 stress(const Mat3& C) const override;
  Mat3 stressIncrement(const Mat3& C, const Mat3& dC) const override;
  double energyDifference(const Mat3& C0, const Mat3& C1) const override;

 private:
  LameParameters lame_;
};

// Compressible Neo-Hooke: W = mu/2 (tr C - 3) - mu ln J + lambda/2 (ln J)^2, J = sqrt(det C). Energy, stress and
// increment of a C with det C <= 0 are NaN (so Newton's line search rejects it), never an exception.
class NeoHooke final : public HyperelasticMaterial {
 public:
  explicit NeoHooke(LameParameters lame);
  double energy(const Mat3& C) const override;
  Mat3 stress(const Mat3& C) const override;
  Mat3 stressIncrement(const Mat3& C, const Mat3& dC) const override;
  double energyDifference(const Mat3& C0, const Mat3& C1) const override;

 private:
  LameParameters lame_;
};

// Maxwell branch in Green strain with a viscous strain Gamma (symmetric): Psi_v = lambda_v/2 tr(A)^2 + mu_v A:A,
// A = E - Gamma; its stress S_v = dPsi_v/dE = lambda_v tr(A) I + 2 mu_v A; evolution dGamma/dt = S_v / eta
// (eta > 0 viscosity), so the dissipation S_v:S_v/eta >= 0. Quadratic in (C, Gamma): its midpoint derivative is an
// exact discrete gradient.
struct ViscousBranch {
  LameParameters moduli;
  double viscosity;
  double energy(const Mat3& C, const Mat3& Gamma) const;
  Mat3 stress(const Mat3& C, const Mat3& Gamma) const;  // S_v (also = 2 dPsi_v/dC = -dPsi_v/dGamma)
};

}  // namespace mpx
