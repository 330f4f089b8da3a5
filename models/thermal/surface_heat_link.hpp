#pragma once
// Heat exchange between one node of a solid's surface and a lumped thermal node (a reservoir,
// a thermo element's node or a fixed temperature): Q = h A (theta_node - T) into the solid node,
// A = int N_a dA its share of the surface, T its discrete temperature (the logarithmic mean in
// an EEM step), theta_node the temperature the lumped node's owner publishes. The heat leaving
// one row enters the other exactly, and the entropy production
// h A (theta_node - T)^2 / (T theta_node) is non-negative. Through a fixed temperature the heat
// (and its entropy Q / theta_node) crosses the system boundary.
#include "models/fe/nodal_thermal_variable.hpp"
#include "models/thermal/heat_link.hpp"

namespace mpx {

class SurfaceHeatLink final : public Component {
 public:
  SurfaceHeatLink(std::string name, int solidThermalDof, NodalThermalVariable thermalVariable, ThermalNodeRef node,
                  double conductance);

  bool isCoupling() const override { return true; }
  // writes the solid node's row and the lumped node's row only, in the columns of the two
  // temperatures
  bool couples(int row, int column, LocalForm) const override {
    return (row == 0 || row == lumpedRow_) && (column == 0 || !node_.ownerVelocity[column - 1]);
  }
  void measure(const double*, Measures&) const override {}
  void eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  void rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  // eem4: the exchange at the solid node's stage temperature
  StageForm stageForm() const override { return StageForm::Own; }
  void stageLocal(const StageArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;

 private:
  // Rows for the solid node at temperature T (slope: dT/ds times the tangent's coefficient).
  void exchange(double T, double slope, const Workspace& ws, LocalSystem& out, Flows& flows) const;
  static std::vector<int> collectDofs(int solidThermalDof, const ThermalNodeRef& node);

  NodalThermalVariable thermalVariable_;  // what the solid node's dof holds
  ThermalNodeRef node_;
  int lumpedRow_ = -1;  // local row of the lumped node's thermal dof, -1 for a fixed temperature
  double conductance_;  // h A
};

}  // namespace mpx
