#include "models/fe/nodal_thermal_variable.hpp"

#include "engine/core/discrete_gradient.hpp"
#include "engine/core/stage_gradient.hpp"

#include <cmath>

namespace mpx {

NodalThermalVariable::NodalThermalVariable(ThermalVariable kind, double capacity, double referenceTemperature)
    : kind_(kind), capacity_(capacity), referenceTemperature_(referenceTemperature) {}

double NodalThermalVariable::temperature(double s) const {
  return kind_ == ThermalVariable::Temperature ? s : referenceTemperature_ * std::exp(s / capacity_);
}

double NodalThermalVariable::fromTemperature(double theta) const {
  return kind_ == ThermalVariable::Temperature ? theta : capacity_ * std::log(theta / referenceTemperature_);
}

// expm1 keeps the entropy form's small departures from theta_R free of cancellation
double NodalThermalVariable::energy(double s) const {
  if (kind_ == ThermalVariable::Temperature) return capacity_ * (s - referenceTemperature_);
  return capacity_ * referenceTemperature_ * std::expm1(s / capacity_);
}

double NodalThermalVariable::entropy(double s) const {
  return kind_ == ThermalVariable::Temperature ? capacity_ * std::log(s / referenceTemperature_) : s;
}

double NodalThermalVariable::energySlope(double s) const {
  return kind_ == ThermalVariable::Temperature ? capacity_ : temperature(s);
}

double NodalThermalVariable::energyCurvature(double s) const {
  return kind_ == ThermalVariable::Temperature ? 0.0 : temperature(s) / capacity_;
}

TemperatureJet NodalThermalVariable::step(double sOld, double sNew) const {
  const double thetaNew = temperature(sNew);
  const LogarithmicMean mean = logarithmicMean(temperature(sOld), thetaNew);
  const double chain = kind_ == ThermalVariable::Temperature ? 1.0 : thetaNew / capacity_;
  return {mean.value, mean.derivative * chain};
}

TemperatureJet NodalThermalVariable::rate(double s, double alpha) const {
  const double theta = temperature(s);
  return {theta, alpha * (kind_ == ThermalVariable::Temperature ? 1.0 : theta / capacity_)};
}

// The temperature form's energy is linear (D_theta e = kappa) and its temperature 1 / D(ln theta);
// the entropy form's entropy is linear (D_s eta = 1) and its temperature D_s e.
NodalThermalVariable::Stage NodalThermalVariable::stage(const StageArgs& args, int dof) const {
  const CollocationRule& rule = *args.rule;
  const double rate = args.stageRate[args.stage][dof];
  const double rateSlope = rule.rate[args.stage][args.column + 1] / args.dt;
  if (kind_ == ThermalVariable::Temperature) {
    const ScalarStageGradient T = stageTemperature(args, dof);
    return {{T.value, T.slope}, {capacity_ * rate, capacity_ * rateSlope}};
  }
  auto energyJet = [&](double s) { return ScalarJet{energy(s), energySlope(s), energyCurvature(s)}; };
  // e(s1) - e(s0) = kappa theta_R exp(s0/kappa) expm1((s1 - s0)/kappa)
  auto energyChange = [&](double s0, double s1) {
    return capacity_ * referenceTemperature_ * std::exp(s0 / capacity_) * std::expm1((s1 - s0) / capacity_);
  };
  const ScalarStageGradient T = scalarStageGradient(energyJet, energyChange, capacity_, args, dof);
  return {{T.value, T.slope}, {T.value * rate, T.slope * rate + T.value * rateSlope}};
}

double NodalThermalVariable::scale() const {
  return kind_ == ThermalVariable::Temperature ? referenceTemperature_ : capacity_;
}

}  // namespace mpx
