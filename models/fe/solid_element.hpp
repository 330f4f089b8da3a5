#pragma once
// One finite-strain solid cell (tet4 or hex8): internal forces from a hyperelastic law and an
// optional Maxwell branch whose viscous strain lives at each quadrature point.
//
// EEM: the force on node a is sum_q w F_m S~ dN_a/dX with F_m the midpoint deformation
// gradient and S~ = 2 D_C W(C, C') the Gonzalez discrete stress (models/fe/discrete_stress),
// plus the branch stress at the midpoint of (C, Gamma), which is exact because the branch
// energy is quadratic there. Since C' - C = F_m^T dF + dF^T F_m exactly, these forces do work
// equal to the change of stored energy, and being F_m S~ they conserve angular momentum.
// The viscous strain follows (Gamma' - Gamma)/dt = S_v/eta, dissipating S_v:S_v/eta.
// Local dofs: node positions, their velocity (momentum) rows, 6 viscous strain components
// (xx, yy, zz, xy, yz, xz) per quadrature point, nodal temperatures.
//
// A thermoelastic cell (docs/theory.md section 9) adds the coupling stress (theta_R - theta) 3 beta K C^-1 and the
// nodes' heat-balance rows T_a [sum_q w N_a (eta_q' - eta_q)/dt] + m_a kappa (theta_a' - theta_a)/dt - heating_a
// (the thermal dofs hold theta or the capacity's entropy, models/fe/nodal_thermal_variable.hpp),
// with T_a the nodal discrete temperature (the logarithmic mean of theta_a, theta_a') and theta = sum_a N_a T_a at
// the points; the heat capacity's entropy is lumped at the nodes (m_a = int N_a dV). Since every cell weighs its
// contribution to node a's row with the same T_a, the rows are T_a times a nodal entropy balance: summed with weight
// 1 / T_a they give the entropy change, summed with weight 1 the energy change, both exactly. The branch's
// dissipation heats the nodes (weights N_a) instead of leaving the system.
#include "models/fe/material.hpp"
#include "models/fe/nodal_thermal_variable.hpp"
#include "models/fe/shape_functions.hpp"

#include "engine/core/component.hpp"

#include <memory>
#include <optional>

namespace mpx {

struct SolidElementSpec {
  std::string name;
  std::vector<int> positionDofs;  // first position dof of each node, cell order
  int velocityShift = 0;          // velocity dof = position dof + velocityShift
  int firstInternalDof = -1;      // the branch's viscous strains, 6 per quadrature point
  std::vector<CellPoint> points;  // stiffness rule
  std::shared_ptr<const HyperelasticMaterial> material;
  std::optional<ViscousBranch> branch;
  std::optional<ThermalMaterial> thermal;
  std::vector<int> thermalDofs;          // thermal dof of each node, cell order (thermal cells only)
  NodalThermalVariable thermalVariable;  // what those dofs hold
};

class SolidElement final : public Component {
 public:
  explicit SolidElement(SolidElementSpec spec);

  // momentum rows depend on positions, strains and, through thermal expansion, temperatures; the
  // viscous rows of a point on positions, that point's own strains and, through the viscosity's
  // activation, temperatures; heat rows on temperatures, and on positions and strains through
  // expansion and the branch's dissipation; nothing depends on velocities (a rate-form heat row
  // reads the position rates, which share the position columns)
  bool couples(int row, int column, LocalForm) const override;
  void measure(const double* z, Measures& out) const override;
  void eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  void rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  // eem4 (models/fe/solid_element_stages.cpp)
  StageForm stageForm() const override { return StageForm::Own; }
  void stageLocal(const StageArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  // a cell's stages share its points' paths: all stages' residuals are computed together
  bool evaluatesStagesTogether() const override { return true; }
  void stageResiduals(const StageArgs& args, Workspace& ws, LocalSystem* out, Flows* flows) const override;

  // Cauchy stress and viscous strain averaged over the quadrature points (for output).
  Mat3 meanCauchyStress(const double* z) const;
  Mat3 meanViscousStrain(const double* z) const;
  // Heat flux -k0 Grad theta and temperature averaged over the quadrature points (0 for a
  // mechanical cell).
  Vec3 meanHeatFlux(const double* z) const;
  double meanTemperature(const double* z) const;

 private:
  using NodePositions = Eigen::Matrix<double, 3, kMaxCellNodes>;
  // How one scheme evaluates a quadrature point (see the .cpp).
  struct PointEvaluation;
  struct NodeTemperatures;
  double pointTemperature(int point, const NodeTemperatures& nodes) const;
  // The branch's fluidity 1/eta at a temperature and its derivative in that temperature.
  struct Fluidity {
    double value = 0.0, slope = 0.0;
  };
  Fluidity fluidityAt(double temperature) const;
  void setFluidity(PointEvaluation& e) const;
  void addDissipation(int point, const PointEvaluation& e, Flows& flows) const;
  // The lumped heat capacity's rows m_a (rate of its energy per volume) with the rates' derivatives in
  // the nodes' dofs.
  void addHeatCapacity(const ShapeValues& energyRates, const ShapeValues& energyRateSlopes, LocalSystem& out) const;
  // Temperatures of the nodes in state z.
  ShapeValues nodeTemperatures(const double* z) const;
  NodePositions positions(const double* z) const;
  Mat3 viscousStrain(const double* z, int point) const;
  // Mark the evaluation of an inadmissible state (an inverted cell, a non-positive stage
  // temperature) with a non-finite residual.
  static void rejectInadmissible(LocalSystem& out);
  // eem4: stages [firstStage, firstStage + count) into out[k] and flows[k], from each point's path
  // through all stages (a tangent for one stage at a time)
  void addStages(const StageArgs& args, int firstStage, int count, LocalSystem* out, Flows* flows) const;
  struct StagePoint;
  void addStagePoint(const StageArgs& args, int stage, const StagePoint& point, const NodalThermalVariable::Stage* node,
                     LocalSystem& out, Flows& flows) const;
  // Add the point's residual rows and tangent columns; materialIncrement(dC) is the change
  // of the hyperelastic (and coupling) stress for a change dC of the end point's C.
  template <class MaterialIncrement>
  void assemblePoint(int point, const PointEvaluation& e, const MaterialIncrement& materialIncrement,
                     LocalSystem& out) const;
  // The point's share of the nodal heat balances: T_a w N_a (entropy rate) and their tangent.
  // entropyRateGradient M gives the rate's derivative with respect to node b's position j as
  // dN_b/dX . M.col(j), with the scheme's coefficients already applied.
  void assembleHeat(int point, const PointEvaluation& e, const Mat3& entropyRateGradient, const NodeTemperatures& nodes,
                    LocalSystem& out) const;

  SolidElementSpec spec_;
  int nodes_;
  int firstThermal_;                                    // local index of the first temperature
  std::optional<VolumeLogarithm> coupling_;             // 3 beta K ln J, thermal cells only
  Eigen::Matrix<double, kMaxCellNodes, 1> nodeVolume_;  // m_a = sum_q w N_a
};

}  // namespace mpx
