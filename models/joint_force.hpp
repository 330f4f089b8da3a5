#pragma once
// A force element on the coordinate of a revolute or prismatic joint: a spring, a viscous
// damper and smoothed Coulomb friction. The coordinate is a function of quadratic invariants I
// of the positions (JointBuilder::coordinateInvariants), so the EEM forces are exact:
//   spring     V(I), force D_I V . grad I(q_mid): revolute k (1 - cos(theta - theta0)),
//              prismatic k/2 (s - s0)^2;
//   dissipation f = c dtheta/dt + F tanh(dtheta/(dt v_s)), force f D_I theta . grad I(q_mid),
//              dissipated energy f dtheta >= 0 per step exactly,
// with theta(I) taken in a chart centred on the step's start (no wrap-around). The dissipated
// power leaves as `dissipated`, or heats a thermal node (a reservoir) when one is given, so an
// isolated system keeps E exactly and produces entropy.
#include "joint_coordinate.hpp"

namespace mpx {

struct JointForceSpec {
  std::string name;
  bool revolute = true;                 // revolute: invariants (u, v); prismatic: (s)
  std::vector<int> positionDofs;        // q of the invariants
  int velocityShift = 0;                // velocity dof = position dof + velocityShift
  std::vector<QuadraticForm> invariants;
  double stiffness = 0.0, rest = 0.0;   // spring
  double damping = 0.0;                 // viscous coefficient
  double friction = 0.0, frictionVelocity = 1.0;  // smoothed Coulomb
  int heatDof = -1;                     // thermal dof heated by the dissipation, -1: none
};

class JointForce final : public Component {
 public:
  explicit JointForce(JointForceSpec spec);

  void measure(const double* z, Measures& out) const override;
  void eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  void rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;

 private:
  static std::vector<int> collectDofs(const JointForceSpec& spec);
  ConstraintVector gather(const double* z, int shift) const;
  Vec3 invariantsAt(const ConstraintVector& q) const;
  // Spring energy as a function of the invariants.
  Jet spring(const Vec3& invariants) const;
  // Generalised dissipative force for a coordinate rate, and its derivative.
  double dissipativeForce(double rate, double* dForce) const;
  // Rows over local dofs: Jacobian of the invariants at q (one row per invariant).
  ConstraintMatrix invariantJacobian(const ConstraintVector& q) const;
  // Add f_I . grad I(q_force) to the momentum rows and heat power to the heat row.
  void applyForce(const Vec3& forceOnInvariants, const ConstraintVector& qForce, LocalSystem& out) const;
  unsigned mask() const { return spec_.revolute ? 3u : 1u; }

  JointForceSpec spec_;
  int n_;  // number of constrained positions
};

}  // namespace mpx
