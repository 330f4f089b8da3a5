#pragma once
// Fourier heat conduction Q = -k0 Grad theta in one cell, in the entropy-weak form that keeps
// both thermodynamic statements exact at the discrete level (docs/theory.md section 9.3):
// node a's heat-balance row gets
//   -T_a sum_q w Grad(N_a / theta) . Q,   theta = sum_b N_b T_b,  Q = -k0 sum_b T_b Grad N_b,
// with T_a the nodal temperatures the cell's heat rows are weighted with (the logarithmic mean
// of theta_a, theta_a' in an EEM step, the stage temperature in an eem4 stage, theta_a in the rate form). Summed over
// a, the rows give no energy (sum_a T_a Grad(N_a/theta) = Grad(1) = 0); divided by T_a and summed, they give the
// entropy production sum_q w k0 |Grad theta|^2 / theta^2 >= 0, on any mesh.
#include "models/fe/nodal_thermal_variable.hpp"
#include "models/fe/shape_functions.hpp"

#include "engine/core/component.hpp"

namespace mpx {

class HeatConduction final : public Component {
 public:
  HeatConduction(std::string name, std::vector<int> thermalDofs, NodalThermalVariable thermalVariable,
                 std::vector<CellPoint> points, double conductivity);

  void measure(const double*, Measures&) const override {}
  void eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  void rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  // eem4: the same rows with the nodes' stage temperatures (docs/theory.md section 13.9)
  StageForm stageForm() const override { return StageForm::Own; }
  void stageLocal(const StageArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;

 private:
  // Rows and tangent for nodal temperatures T with derivatives slope (dT_a/ds_a times the
  // tangent's coefficient, s_a the node's dof).
  void assemble(const ShapeValues& T, const ShapeValues& slope, LocalSystem& out) const;

  NodalThermalVariable thermalVariable_;
  std::vector<CellPoint> points_;
  double conductivity_;
  int nodes_;
};

}  // namespace mpx
