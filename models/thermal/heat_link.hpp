#pragma once
// Fourier heat conduction between two thermal nodes, Q = k (theta_b - theta_a) into a, with the
// node temperatures their owners publish (discrete temperatures in an EEM step), so the heat
// leaving one node enters the other exactly and the entropy production
// k (theta_a - theta_b)^2 / (theta_a theta_b) is non-negative. A node with a prescribed
// temperature has no dof: the heat through it is the boundary-heat flow.
#include "engine/core/component.hpp"

namespace mpx {

// A thermal node as a link sees it: its index, its own thermal dof (-1 when prescribed), the
// global dofs its owner's published temperature derivative refers to, and which of them are
// velocities: a temperature is a derivative of the internal energy, which holds no kinetic
// energy, so its derivative there is zero.
struct ThermalNodeRef {
  int node = -1;
  int thermalDof = -1;
  std::vector<int> ownerDofs;
  std::vector<bool> ownerVelocity;
};

class HeatLink final : public Component {
 public:
  HeatLink(std::string name, ThermalNodeRef a, ThermalNodeRef b, double conductivity);

  bool isCoupling() const override { return true; }
  // writes the two thermal rows only, in the columns the node temperatures depend on
  bool couples(int row, int column, LocalForm) const override {
    return (row == localThermal_[0] || row == localThermal_[1]) && temperatureColumn_[column];
  }
  void measure(const double* z, Measures& out) const override;
  void eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  void rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  // eem4: no energy: heat between the temperatures each stage publishes
  StageForm stageForm() const override { return StageForm::RateAtStages; }

 private:
  // Residual -Q on both nodes' thermal rows and its tangent through the node temperatures.
  void exchange(const Workspace& ws, LocalSystem& out, Flows& flows) const;
  static std::vector<int> unionDofs(const ThermalNodeRef& a, const ThermalNodeRef& b);
  int localIndex(int globalDof) const;

  ThermalNodeRef ends_[2];
  std::vector<int> ownerToLocal_[2];  // owner-local dof -> link-local dof
  int localThermal_[2] = {-1, -1};
  std::vector<bool> temperatureColumn_;  // per link-local dof: a node temperature depends on it
  double conductivity_;
};

}  // namespace mpx
