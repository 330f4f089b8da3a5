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
// (xx, yy, zz, xy, yz, xz) per quadrature point.
#include "models/fe/material.hpp"
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
};

class SolidElement final : public Component {
 public:
  explicit SolidElement(SolidElementSpec spec);

  // momentum rows depend on positions and every viscous strain, the viscous rows of a point on
  // positions and that point's own strains; nothing depends on velocities
  bool couples(int row, int column) const override {
    const int strains = 6 * nodes_;
    if (row < 3 * nodes_ || (column >= 3 * nodes_ && column < strains)) return false;
    return row < strains || column < strains || (row - strains) / 6 == (column - strains) / 6;
  }
  void measure(const double* z, Measures& out) const override;
  void eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  void rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;

  // Cauchy stress and viscous strain averaged over the quadrature points (for output).
  Mat3 meanCauchyStress(const double* z) const;
  Mat3 meanViscousStrain(const double* z) const;

 private:
  using NodePositions = Eigen::Matrix<double, 3, kMaxCellNodes>;
  // How one scheme evaluates a quadrature point (see the .cpp).
  struct PointEvaluation;
  NodePositions positions(const double* z) const;
  Mat3 viscousStrain(const double* z, int point) const;
  // Mark the evaluation of a state with an inverted cell as inadmissible.
  static void rejectInverted(LocalSystem& out);
  // Add the point's residual rows and tangent columns; materialIncrement(dC) is the change
  // of the hyperelastic stress for a change dC of the end point's C.
  template <class MaterialIncrement>
  void assemblePoint(int point, const PointEvaluation& e, const MaterialIncrement& materialIncrement,
                     LocalSystem& out) const;

  SolidElementSpec spec_;
  int nodes_;
};

}  // namespace mpx
