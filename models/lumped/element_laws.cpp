#include "models/lumped/element_laws.hpp"

#include <cmath>
#include <stdexcept>

namespace mpx {

namespace {

// Chain rule for a jet in (x, s, gamma) with x = x(c): returns the jet in (c, s, gamma).
Jet composeFirstArgument(const Jet& h, double dx, double d2x) {
  Jet out = h;
  out.grad[0] = h.grad[0] * dx;
  out.hess(0, 0) = h.hess(0, 0) * dx * dx + h.grad[0] * d2x;
  for (int j = 1; j < 3; ++j) out.hess(0, j) = out.hess(j, 0) = h.hess(0, j) * dx;
  return out;
}

}  // namespace

HookeLaw::HookeLaw(double stiffness, double restLength, double branchStiffness)
    : stiffness_(stiffness), restLength_(restLength), branchStiffness_(branchStiffness) {}

Jet HookeLaw::energy(const Vec3& args) const {
  // in the elongation u = sqrt(c) - lambda0 first, then chain to c
  const double lambda = std::sqrt(args[0]);
  const double u = lambda - restLength_;
  const double w = u - args[2];
  Jet h;
  h.value = 0.5 * stiffness_ * u * u + 0.5 * branchStiffness_ * w * w;
  h.grad[0] = stiffness_ * u + branchStiffness_ * w;
  h.grad[2] = -branchStiffness_ * w;
  h.hess(0, 0) = stiffness_ + branchStiffness_;
  h.hess(2, 2) = branchStiffness_;
  h.hess(0, 2) = h.hess(2, 0) = -branchStiffness_;
  return composeFirstArgument(h, 0.5 / lambda, -0.25 / (lambda * lambda * lambda));
}

Jet HookeLaw::entropy(const Vec3&) const { return Jet{}; }

ThermoElasticLaw::ThermoElasticLaw(const ThermoElasticParameters& parameters, ThermalVariable variable)
    : p_(parameters), variable_(variable), logRestLength_(std::log(parameters.restLength)) {
  if (variable_ == ThermalVariable::Entropy && p_.stiffnessCurvature != 0.0)
    throw std::invalid_argument(
        "the entropy-based formulation needs a stiffness linear in temperature (stiffness_curvature = 0)");
}

double ThermoElasticLaw::logStrain(double c) const { return p_.hasStretch ? 0.5 * std::log(c) - logRestLength_ : 0.0; }

Jet ThermoElasticLaw::toStretchInvariant(const Jet& h, double c) const {
  if (!p_.hasStretch) return h;
  return composeFirstArgument(h, 0.5 / c, -0.5 / (c * c));
}

Jet ThermoElasticLaw::energy(const Vec3& args) const {
  return variable_ == ThermalVariable::Temperature ? energyTemperatureForm(args) : energyEntropyForm(args);
}

Jet ThermoElasticLaw::entropy(const Vec3& args) const {
  if (variable_ == ThermalVariable::Temperature) return entropyTemperatureForm(args);
  Jet identity;  // the entropy is the state variable itself
  identity.value = args[1];
  identity.grad[1] = 1.0;
  return identity;
}

Jet ThermoElasticLaw::energyTemperatureForm(const Vec3& args) const {
  const double L = logStrain(args[0]);
  const double theta = args[1];
  const double dT = theta - p_.referenceTemperature;
  const double C = p_.stiffness + p_.stiffnessSlope * dT + p_.stiffnessCurvature * dT * dT;
  const double dC = p_.stiffnessSlope + 2.0 * p_.stiffnessCurvature * dT;
  const double d2C = 2.0 * p_.stiffnessCurvature;
  // A(theta) = C - theta C' multiplies L^2/2; A' = -theta C'', A'' = -C''
  const double A = C - theta * dC;
  const double dA = -theta * d2C;
  const double d2A = -d2C;
  const double w = L - args[2];
  const double mu = p_.branchStiffness;
  Jet h;
  h.value = 0.5 * A * L * L + p_.coupling * p_.referenceTemperature * L + p_.heatCapacity * dT + 0.5 * mu * w * w;
  h.grad[0] = A * L + p_.coupling * p_.referenceTemperature + mu * w;
  h.grad[1] = 0.5 * dA * L * L + p_.heatCapacity;
  h.grad[2] = -mu * w;
  h.hess(0, 0) = A + mu;
  h.hess(1, 1) = 0.5 * d2A * L * L;
  h.hess(2, 2) = mu;
  h.hess(0, 1) = h.hess(1, 0) = dA * L;
  h.hess(0, 2) = h.hess(2, 0) = -mu;
  return toStretchInvariant(h, args[0]);
}

Jet ThermoElasticLaw::entropyTemperatureForm(const Vec3& args) const {
  const double L = logStrain(args[0]);
  const double theta = args[1];
  const double dT = theta - p_.referenceTemperature;
  const double dC = p_.stiffnessSlope + 2.0 * p_.stiffnessCurvature * dT;
  const double d2C = 2.0 * p_.stiffnessCurvature;
  Jet h;
  h.value = temperatureFormEntropy(L, theta);
  h.grad[0] = -dC * L + p_.coupling;
  h.grad[1] = -0.5 * d2C * L * L + p_.heatCapacity / theta;
  h.hess(0, 0) = -dC;
  h.hess(1, 1) = -p_.heatCapacity / (theta * theta);
  h.hess(0, 1) = h.hess(1, 0) = -d2C * L;
  return toStretchInvariant(h, args[0]);
}

double ThermoElasticLaw::temperatureFormEntropy(double L, double theta) const {
  const double dC = p_.stiffnessSlope + 2.0 * p_.stiffnessCurvature * (theta - p_.referenceTemperature);
  return -0.5 * dC * L * L + p_.coupling * L + p_.heatCapacity * std::log(theta / p_.referenceTemperature);
}

Jet ThermoElasticLaw::energyEntropyForm(const Vec3& args) const {
  const double L = logStrain(args[0]);
  const double cap = p_.heatCapacity;
  const double C1 = p_.stiffnessSlope;
  const double A = p_.stiffness - C1 * p_.referenceTemperature;
  // theta = theta_ref exp(phi), phi = (eta + C1/2 L^2 - alpha L)/c
  const double phiL = (C1 * L - p_.coupling) / cap;
  const double theta = p_.referenceTemperature * std::exp((args[1] + 0.5 * C1 * L * L - p_.coupling * L) / cap);
  const double w = L - args[2];
  const double mu = p_.branchStiffness;
  Jet h;
  h.value = 0.5 * A * L * L + p_.coupling * p_.referenceTemperature * L + cap * (theta - p_.referenceTemperature) +
            0.5 * mu * w * w;
  h.grad[0] = A * L + p_.coupling * p_.referenceTemperature + cap * theta * phiL + mu * w;
  h.grad[1] = theta;
  h.grad[2] = -mu * w;
  h.hess(0, 0) = A + cap * theta * (phiL * phiL + C1 / cap) + mu;
  h.hess(1, 1) = theta / cap;
  h.hess(2, 2) = mu;
  h.hess(0, 1) = h.hess(1, 0) = theta * phiL;
  h.hess(0, 2) = h.hess(2, 0) = -mu;
  return toStretchInvariant(h, args[0]);
}

double ThermoElasticLaw::thermalVariableFromTemperature(double c, double theta, double) const {
  if (variable_ == ThermalVariable::Temperature) return theta;
  return temperatureFormEntropy(logStrain(c), theta);
}

double ThermoElasticLaw::thermalVariableFromEntropy(double c, double eta, double) const {
  if (variable_ == ThermalVariable::Entropy) return eta;
  // invert eta(L, theta) for theta: Newton in log(theta), eta is increasing in theta
  const double L = logStrain(c);
  double logTheta = std::log(p_.referenceTemperature);
  for (int iteration = 0; iteration < 100; ++iteration) {
    const double theta = std::exp(logTheta);
    const double defect = temperatureFormEntropy(L, theta) - eta;
    const double slope = theta * (-p_.stiffnessCurvature * L * L + p_.heatCapacity / theta);
    const double step = defect / slope;
    logTheta -= step;
    if (std::abs(step) < 1e-15) return std::exp(logTheta);
  }
  throw std::invalid_argument("cannot find a temperature for the given initial entropy");
}

}  // namespace mpx
