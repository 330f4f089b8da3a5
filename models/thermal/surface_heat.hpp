#pragma once
// Heat through a solid's surface into one of its nodes: a prescribed flux q(t) (W/m^2,
// Neumann) and convection h (theta_ambient - T) to an ambient temperature (Robin), over the
// node's share A = int N_a dA of the surface. T is the temperature the node's heat row is
// weighted with (the logarithmic mean of theta, theta' in an EEM step), so the heat enters the
// energy balance exactly; the flux brings entropy q A / T, the convection h A (theta_ambient - T)
// / theta_ambient, and the rest, h A (theta_ambient - T)^2 / (T theta_ambient) >= 0, is produced.
#include "models/fe/nodal_thermal_variable.hpp"

#include "engine/core/component.hpp"
#include "engine/core/time_function.hpp"

namespace mpx {

struct SurfaceHeatSpec {
  std::string name;
  int thermalDof = -1;
  NodalThermalVariable thermalVariable;  // what the dof holds
  double area = 0.0;                     // int N_a dA
  double flux = 0.0;                     // amplitude of the prescribed flux (W/m^2), times profile(t)
  TimeFunction profile = TimeFunction::constant(1.0);
  double convection = 0.0;  // h (W/(m^2 K))
  double ambientTemperature = 1.0;
};

class SurfaceHeat final : public Component {
 public:
  explicit SurfaceHeat(SurfaceHeatSpec spec);

  void measure(const double*, Measures&) const override {}
  void eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  void rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  // eem4: the exchange at the solid node's stage temperature
  StageForm stageForm() const override { return StageForm::Own; }
  void stageLocal(const StageArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;

 private:
  // Row -heat at node temperature T (dT/ds times the tangent's coefficient: slope) and flux
  // density q; the heat and its entropy cross the boundary.
  void exchange(double T, double slope, double q, LocalSystem& out, Flows& flows) const;
  SurfaceHeatSpec spec_;
};

}  // namespace mpx
