#pragma once
// What a thermal solid's nodal dof holds (docs/theory.md section 9.7): the temperature theta
// (temperature form) or the heat capacity's entropy per unit reference volume
// s = kappa ln(theta / theta_R) (entropy form), in which the capacity's energy
// kappa theta_R (exp(s / kappa) - 1) is in closed form. Every component that touches a solid's
// thermal dofs reads its temperatures through this class, so both forms assemble the same rows
// and differ only in the unknown Newton solves for. (Prescribed temperatures, which the
// assembler imposes on the dof itself, exist in the temperature form only.)
#include "engine/core/model.hpp"

namespace mpx {

// A node temperature and its derivative with respect to the node's dof (times the tangent's
// coefficient where stated).
struct TemperatureJet {
  double value = 0.0;
  double slope = 0.0;
};

class NodalThermalVariable {
 public:
  NodalThermalVariable() = default;
  NodalThermalVariable(ThermalVariable kind, double capacity, double referenceTemperature);

  ThermalVariable kind() const { return kind_; }
  double temperature(double s) const;
  double fromTemperature(double theta) const;
  // The heat capacity's energy kappa (theta - theta_R) and entropy kappa ln(theta / theta_R) per
  // unit volume; the energy's first and second derivatives in s.
  double energy(double s) const;
  double entropy(double s) const;
  double energySlope(double s) const;
  double energyCurvature(double s) const;
  // The discrete temperature of a step s -> s' (the logarithmic mean of theta(s), theta(s'),
  // which is D_s energy / D_s entropy in either form) and its derivative in s'.
  TemperatureJet step(double sOld, double sNew) const;
  // theta(s) and alpha dtheta/ds, for a rate evaluation with tangent coefficient alpha.
  TemperatureJet rate(double s, double alpha) const;
  // An eem4 stage of the node's dof: the stage temperature D_s e / D_s eta along the dof's stage
  // polynomial (docs/theory.md section 13.9) and the capacity's energy rate D_s e s' (per unit
  // volume), with their derivatives in the dof's value at stage args.column.
  struct Stage {
    TemperatureJet temperature;
    TemperatureJet energyRate;
  };
  Stage stage(const StageArgs& args, int dof) const;
  // Newton's scale of the dof.
  double scale() const;

 private:
  ThermalVariable kind_ = ThermalVariable::Temperature;
  double capacity_ = 1.0;              // kappa
  double referenceTemperature_ = 1.0;  // theta_R
};

}  // namespace mpx
