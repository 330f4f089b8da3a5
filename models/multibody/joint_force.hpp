#pragma once
// A force element on the coordinate of a revolute or prismatic joint: a spring, a Maxwell
// branch (spring in series with a dashpot, internal variable gamma), a viscous damper and
// smoothed Coulomb friction. The coordinate is a function of quadratic invariants I of the
// positions (JointBuilder::coordinateInvariants), so the EEM forces are exact:
//   energy     e(I, gamma), force D_I e . grad I(q_mid): revolute k (1 - cos(theta - theta0))
//              + kb (1 - cos(theta - gamma)); prismatic k/2 (s - s0)^2 + k3/4 (s - s0)^4
//              + kb/2 (s - gamma)^2; nu (gamma' - gamma)/dt = -D_gamma e dissipates
//              (D_gamma e)^2 / nu;
//   dissipation f = c dtheta/dt + F tanh(dtheta/(dt v_s)), force f D_I theta . grad I(q_mid),
//              dissipated energy f dtheta >= 0 per step exactly,
// with theta(I) taken in a chart centred on the step's start (no wrap-around). Optional stops
// at lower <= theta <= upper add the potential k_s/3 delta^3 of the depth delta beyond the
// nearer limit (C2: zero with its first two derivatives at contact) and the damping force
// c_s delta^2 dtheta/dt (in EEM with delta^2 averaged over the step's ends), which dissipates
// like the damper; a revolute stop's angle is taken in a chart centred on the middle of the
// range, so the range must be below a full turn. The dissipated
// power leaves as `dissipated`, or heats a thermal node (a reservoir) when one is given, so an
// isolated system keeps E exactly and produces entropy.
#include "models/multibody/joint_coordinate.hpp"

#include <optional>

namespace mpx {

// Limits of a joint coordinate (relative to its t = 0 value, as rest), a stop's stiffness
// k_s and damping c_s.
struct JointStop {
  double lower = 0.0, upper = 0.0;
  double stiffness = 0.0, damping = 0.0;
};

struct JointForceSpec {
  std::string name;
  bool revolute = true;           // revolute: invariants (u, v); prismatic: (s)
  std::vector<int> positionDofs;  // q of the invariants
  int velocityShift = 0;          // velocity dof = position dof + velocityShift
  std::vector<QuadraticForm> invariants;
  double stiffness = 0.0, rest = 0.0;             // spring
  double cubicStiffness = 0.0;                    // prismatic: k3 of k3/4 (s - s0)^4
  double branchStiffness = 0.0, viscosity = 1.0;  // Maxwell branch (with internalDof)
  int internalDof = -1;                           // gamma of the Maxwell branch, -1: none
  double damping = 0.0;                           // viscous coefficient
  double friction = 0.0, frictionVelocity = 1.0;  // smoothed Coulomb
  int heatDof = -1;                               // thermal dof heated by the dissipation, -1: none
  std::optional<JointStop> stop;                  // stops at the coordinate's limits, none: free
};

class JointForce final : public Component {
 public:
  explicit JointForce(JointForceSpec spec);

  // local order q, v, heat, internal: every row but the kinematic ones, of the coordinates the
  // invariants touch and of heat and gamma, against the same columns. Velocities are read by the
  // dissipative forces of the rate and stage forms only: the step's coordinate rate is the
  // positions' (s' - s)/dt
  bool couples(int row, int column, LocalForm form) const override {
    const bool velocityColumn = column >= n_ && column < 2 * n_;
    return row >= n_ && reachedByInvariants(row) && reachedByInvariants(column) &&
           (!velocityColumn || (form != LocalForm::Step && dissipatesByRate()));
  }
  void measure(const double* z, Measures& out) const override;
  void eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  void rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  // eem4: the energy-consistent stage gradient of e(I, gamma) (docs/theory.md section 13.2) and
  // the dissipative forces in their rate form at each stage
  StageForm stageForm() const override { return StageForm::Own; }
  void stageLocal(const StageArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;

 private:
  static std::vector<int> collectDofs(const JointForceSpec& spec);
  // Whether a damper, friction or a stop's damping acts on the coordinate rate.
  bool dissipatesByRate() const {
    return spec_.damping > 0.0 || spec_.friction > 0.0 || (spec_.stop && spec_.stop->damping > 0.0);
  }
  // False for the position or velocity of a coordinate no invariant touches.
  bool reachedByInvariants(int local) const {
    if (local >= 2 * n_) return true;
    for (const QuadraticForm& invariant : spec_.invariants)
      if (invariant.touches(local % n_)) return true;
    return false;
  }
  ConstraintVector gather(const double* z, int shift) const;
  // (I_0, I_1, gamma) of a state; unused slots are 0.
  Vec3 arguments(const double* z) const;
  // Stored energy e(I, gamma) with gradient and Hessian: springs and stops.
  Jet energy(const Vec3& args) const;
  Jet springEnergy(const Vec3& args) const;
  // Generalised dissipative force for a coordinate rate, and its derivative.
  double dissipativeForce(double rate, double* dForce) const;
  // Depth beyond the nearer stop, its gradient and Hessian over the arguments (zero inside the range).
  struct Penetration {
    double depth = 0.0;
    Vec3 grad = Vec3::Zero();
    Mat3 hess = Mat3::Zero();
  };
  Penetration penetration(const Vec3& args) const;
  // The stop potential k_s/3 delta^3 over the arguments.
  Jet stopEnergy(const Vec3& args) const;
  // d(I_0, I_1, gamma)/dq at q: one row per argument slot, zero for gamma and unused slots.
  using ArgumentJacobian = Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kMaxConstrainedDofs>;
  ArgumentJacobian invariantJacobian(const ConstraintVector& q) const;
  // The rows of d(I_0, I_1, gamma)/dz over all `count` local dofs at z.
  void argumentRows(const double* z, int count, LocalRow (&rows)[3]) const;
  // The dissipative force f along the coordinate (damper, friction, stop damping) at arguments
  // a, invariant Jacobian J and velocities v, in rate form: adds its pull to the momentum rows
  // with the tangent alpha d/d(q, v) and returns its power f rate, with the power's derivatives
  // (times alpha).
  double addDissipativeForce(const Vec3& a, const ConstraintVector& v, const ArgumentJacobian& J, double alpha,
                             LocalSystem& out, ConstraintRow& dPowerDq, ConstraintRow& dPowerDv) const;
  unsigned mask() const;
  // Send the dissipated power (with its tangent row over q, v and gamma) to the heat node, or
  // to the flows.
  void deposit(double power, const ConstraintRow& dPowerDq, const ConstraintRow& dPowerDv, double dPowerDgamma,
               LocalSystem& out, Flows& flows) const;

  JointForceSpec spec_;
  int n_;  // number of constrained positions
  int localHeat_, localInternal_;
};

}  // namespace mpx
