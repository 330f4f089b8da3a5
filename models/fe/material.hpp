#pragma once
// Pointwise finite-strain material laws, pure functions of the right Cauchy-Green tensor C = F^T F (symmetric
// positive definite) per unit reference volume: hyperelastic laws W(C) with their second Piola-Kirchhoff stress
// S = 2 dW/dC and its directional derivative, and a Maxwell branch in Green strain with a viscous strain Gamma.
#include <Eigen/Dense>

namespace mpx {

using Mat3 = Eigen::Matrix3d;

// Green-Lagrange strain E = (C - I)/2.
inline Mat3 greenStrain(const Mat3& C) { return 0.5 * (C - Mat3::Identity()); }

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
  // W(C0 + dC) - W(C0) from the change dC without cancellation: its error is round-off of the
  // difference, not of W, which the Gonzalez quotient divides by |dC|^2. A dC computed from the
  // change of F (not as C1 - C0) carries no round-off of C either.
  virtual double energyDifference(const Mat3& C0, const Mat3& dC) const = 0;
};

// W = lambda/2 (tr E)^2 + mu E:E, E = (C - I)/2
class SaintVenantKirchhoff final : public HyperelasticMaterial {
 public:
  explicit SaintVenantKirchhoff(LameParameters lame);
  double energy(const Mat3& C) const override;
  Mat3 stress(const Mat3& C) const override;
  Mat3 stressIncrement(const Mat3& C, const Mat3& dC) const override;
  double energyDifference(const Mat3& C0, const Mat3& dC) const override;

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
  double energyDifference(const Mat3& C0, const Mat3& dC) const override;

 private:
  LameParameters lame_;
};

// W = c ln J, J = sqrt(det C): the volumetric part of a thermoelastic coupling (c = 3 beta K), as a law of C so that
// its discrete derivative is the same Gonzalez stress as any hyperelastic energy's. NaN for det C <= 0.
class VolumeLogarithm final : public HyperelasticMaterial {
 public:
  explicit VolumeLogarithm(double coefficient);
  double energy(const Mat3& C) const override;
  Mat3 stress(const Mat3& C) const override;
  Mat3 stressIncrement(const Mat3& C, const Mat3& dC) const override;
  double energyDifference(const Mat3& C0, const Mat3& dC) const override;

 private:
  double coefficient_;
};

// ln J(C0 + dC) - ln J(C0) without cancellation (NaN unless both determinants are positive).
double logJacobianChange(const Mat3& C0, const Mat3& dC);

// Thermal constants of a thermoelastic solid (docs/theory.md section 9): free energy per reference volume
//   Psi(C, theta) = W(C) - 3 beta K (theta - theta_R) ln J + kappa [theta - theta_R - theta ln(theta/theta_R)],
// so heating expands (beta > 0), entropy eta = 3 beta K ln J + kappa ln(theta/theta_R) and internal energy
// e = W + 3 beta K theta_R ln J + kappa (theta - theta_R); Fourier conduction Q = -k0 Grad theta.
struct ThermalMaterial {
  double expansion = 0.0;             // beta, linear thermal expansion coefficient (1/K)
  double bulkModulus = 0.0;           // K = lambda + 2 mu/3 of the elastic law
  double capacity = 1.0;              // kappa, heat capacity per reference volume (J/(m^3 K))
  double conductivity = 0.0;          // k0 (W/(m K))
  double referenceTemperature = 1.0;  // theta_R (K)
  double viscosityActivation = 0.0;   // a of a Maxwell branch's eta(theta) = eta exp(-a (theta - theta_R)) (1/K)
  double couplingModulus() const { return 3.0 * expansion * bulkModulus; }
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
