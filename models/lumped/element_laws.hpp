#pragma once
// Constitutive laws of lumped elements: the energy e(c, s, gamma) and entropy eta(c, s, gamma)
// as functions of the stretch invariant c = |x_b - x_a|^2, the thermal variable s held in the
// state (temperature or entropy) and an internal variable gamma. Arguments a law does not use
// are ignored (their derivatives are zero). Each returns value, gradient and Hessian.
#include "engine/core/discrete_gradient.hpp"
#include "engine/core/model.hpp"

namespace mpx {

class ElementLaw {
 public:
  virtual ~ElementLaw() = default;
  virtual Jet energy(const Vec3& args) const = 0;
  virtual Jet entropy(const Vec3& args) const = 0;
  // True when the entropy is linear in the arguments: then every discrete gradient of it is
  // its constant gradient, and elements skip the quotients (and their round-off).
  virtual bool linearEntropy() const { return false; }
};

// Isothermal spring with a Maxwell branch, in the elongation u = lambda - lambda0 (lambda = sqrt c):
//   e = k/2 u^2 + kBranch/2 (u - gamma)^2,   gamma: viscous elongation of the branch.
// kBranch = 0 gives the plain linear (Hooke) spring.
class HookeLaw final : public ElementLaw {
 public:
  HookeLaw(double stiffness, double restLength, double branchStiffness);
  Jet energy(const Vec3& args) const override;
  Jet entropy(const Vec3& args) const override;
  bool linearEntropy() const override { return true; }

 private:
  double stiffness_, restLength_, branchStiffness_;
};

struct ThermoElasticParameters {
  double stiffness = 0.0;           // C(theta_ref)
  double stiffnessSlope = 0.0;      // dC/dtheta at theta_ref
  double stiffnessCurvature = 0.0;  // d2C/dtheta2 / 2: C = C0 + C1 dT + C2 dT^2
  double coupling = 0.0;            // alpha, thermo-mechanical coupling
  double restLength = 1.0;          // lambda0
  double heatCapacity = 1.0;        // c > 0
  double referenceTemperature = 1.0;
  double branchStiffness = 0.0;  // mu of the Maxwell branch (0: none)
  bool hasStretch = true;        // false: a pure heat capacity (reservoir)
};

// Thermo-spring of docs/theory.md section 4.6 (after [Conde Martín 2016] eq 2.19, docs/references.md) in the
// logarithmic strain L = log(lambda/lambda0), with an optional Maxwell branch on the viscous strain gamma:
//   Psi = C(theta)/2 L^2 - alpha (theta - theta_ref) L + c (theta - theta_ref - theta log(theta/theta_ref))
//         + mu/2 (L - gamma)^2
//   eta = -dPsi/dtheta,  e = Psi + theta eta = (C - theta C')/2 L^2 + alpha theta_ref L + c (theta - theta_ref)
//         + mu/2 (L - gamma)^2.
// In entropy form (needs C linear in theta, [Conde Martín 2016] eq 2.27-2.28), theta(L, eta) is explicit:
//   theta = theta_ref exp((eta + C1/2 L^2 - alpha L)/c),  e = (C0 - C1 theta_ref)/2 L^2 + alpha theta_ref L
//           + c (theta - theta_ref) + mu/2 (L - gamma)^2,  and the entropy argument is eta itself.
// Without stretch (L = 0) this is a heat reservoir of capacity c.
class ThermoElasticLaw final : public ElementLaw {
 public:
  // Throws std::invalid_argument when the entropy form is asked of a non-linear C(theta).
  ThermoElasticLaw(const ThermoElasticParameters& parameters, ThermalVariable variable);
  Jet energy(const Vec3& args) const override;
  Jet entropy(const Vec3& args) const override;
  // in entropy form the entropy argument is the entropy itself
  bool linearEntropy() const override { return variable_ == ThermalVariable::Entropy; }

  // The state's thermal variable for a given temperature or entropy at stretch c and gamma.
  double thermalVariableFromTemperature(double c, double theta, double gamma) const;
  double thermalVariableFromEntropy(double c, double eta, double gamma) const;

 private:
  double logStrain(double c) const;
  double temperatureFormEntropy(double logStrain, double theta) const;
  Jet energyTemperatureForm(const Vec3& args) const;
  Jet energyEntropyForm(const Vec3& args) const;
  Jet entropyTemperatureForm(const Vec3& args) const;
  // Turn a jet in (L, s, gamma) into a jet in (c, s, gamma).
  Jet toStretchInvariant(const Jet& inLogStrain, double c) const;

  ThermoElasticParameters p_;
  ThermalVariable variable_;
  double logRestLength_;
};

}  // namespace mpx
