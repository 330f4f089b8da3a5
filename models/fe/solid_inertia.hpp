#pragma once
// Inertia of one solid cell: the consistent mass matrix M_ab = int rho N_a N_b dV (constant),
// the weight of the cell under uniform gravity, and the kinematic rows x' = v of the nodes the
// cell owns (each node of a body is owned by exactly one of its cells). Rows:
//   kinematics (owned nodes)  (x' - x)/dt - (v + v')/2        rate form: xdot - v
//   momentum (all nodes)      sum_b M_ab (v_b' - v_b)/dt - f_a  rate form: sum_b M_ab vdot_b - f_a
// with f_a = g sum_b M_ab, whose potential -f_a.x_a is part of the energy. The kinetic energy
// v.Mv/2, momentum sum M_ab v_b and angular momentum sum M_ab x_a x v_b are exact sums.
#include "models/fe/shape_functions.hpp"

#include "engine/core/component.hpp"

namespace mpx {

struct SolidInertiaSpec {
  std::string name;
  std::vector<int> positionDofs;  // first position dof of each node, cell order
  int velocityShift = 0;
  std::vector<bool> ownsNode;     // writes the node's kinematic rows
  std::vector<CellPoint> points;  // mass rule
  double density = 0.0;
  Vec3 gravity = Vec3::Zero();
};

class SolidInertia final : public Component {
 public:
  explicit SolidInertia(const SolidInertiaSpec& spec);

  bool couples(int row, int column, LocalForm) const override;
  void measure(const double* z, Measures& out) const override;
  // the nodes the cell owns, as points
  void spatialVectors(std::vector<SpatialVector>& out) const override;
  void eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  void rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  // eem4: a kinetic energy quadratic in the velocities and a constant weight
  StageForm stageForm() const override { return StageForm::RateAtStages; }

 private:
  using NodeVectors = Eigen::Matrix<double, 3, kMaxCellNodes>;
  // Node positions (shift 0) or velocities (shift = velocityShift) of z, one column each.
  NodeVectors gather(const double* z, int shift) const;
  // Momentum rows sum_b M_ab rate_b - f_a, and the kinematic rows from `kinematics` (one
  // column per node), with their tangent coefficients if `tangent` (a residual-only evaluation
  // leaves the local tangent unread).
  void addRows(const NodeVectors& rate, double rateCoefficient, const NodeVectors& kinematics,
               double positionCoefficient, double velocityCoefficient, bool tangent, LocalSystem& out) const;

  std::vector<int> firstDofs_;
  int velocityShift_, nodes_;
  std::vector<bool> ownsNode_;
  Eigen::Matrix<double, kMaxCellNodes, kMaxCellNodes> mass_;
  NodeVectors weight_;  // f_a, one column per node
};

}  // namespace mpx
