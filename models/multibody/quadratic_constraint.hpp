#pragma once
// Holonomic constraints Phi_k(q) = 1/2 q.H_k q + g_k.q + c_k = 0 on a set of position dofs:
// director rigidity, spherical, revolute, prismatic, ... joints and distances are all quadratic
// in the director formulation (docs/theory.md sections 6-7). For a quadratic Phi the discrete
// gradient of V = lambda Phi + kappa/2 Phi^2 is exact:
//   D V = (lambda + kappa (Phi(q) + Phi(q'))/2) grad Phi(q_mid),
// so constraint forces do no spurious work. Penalty: lambda = 0. Augmented Lagrangian: a
// multiplier lambda per constraint, solved by Newton together with the positions from the row
// Phi(q') = 0, so the constraint holds at every step to Newton's tolerance and the energy
// (which includes lambda Phi) is exact; kappa regularises the saddle point. The rate form
// (midpoint, trapezoidal, IDA) is the stabilised index-2 GGL form with a second multiplier mu
// per constraint: q' - v + mu grad Phi = 0, Phi(q) = 0, grad Phi . v = 0 (the multiplier
// block is algebraic for IDA). In an eem4 step (docs/theory.md section 13.7) lambda is linear
// over the step (a value per stage); the forces and the rate of Phi are projected onto the
// stages' test functions with a quadrature exact for their polynomial integrands, so that the
// constraint forces do no work over the step and the penalty energy's change is exact, and,
// with grad Phi taken on the line through the stage positions, exert no moment.
#include "engine/core/component.hpp"
#include "models/multibody/quadratic_form.hpp"

#include <vector>

namespace mpx {

enum class Enforcement { Penalty, AugmentedLagrangian };

struct ConstraintSpec {
  std::string name;
  std::vector<int> positionDofs;  // global; q in the forms is these dofs in this order
  int velocityShift = 0;          // velocity dof = position dof + velocityShift
  std::vector<QuadraticForm> forms;
  Enforcement enforcement = Enforcement::Penalty;
  double stiffness = 0.0;
  int firstMultiplierDof = -1;  // augmented Lagrangian: lambda_0 ... lambda_m-1, then mu_0 ... mu_m-1
  bool leadingGap = false;      // forms 0-2 are the components of the gap between two points
};

class QuadraticConstraint final : public Component {
 public:
  explicit QuadraticConstraint(ConstraintSpec spec);

  // The pairs the forms' coordinates reach (local order: q, v, lambda, mu): only GGL's rows (the
  // rate form) write kinematic rows and read velocities.
  bool couples(int row, int column, LocalForm form) const override;
  const ConstraintSpec& spec() const { return spec_; }
  // Form k is implied by other forms (a redundant condition, e.g. the out-of-plane conditions
  // of a planar loop of revolute joints): its multipliers are held at zero and its rows drop
  // out of the saddle point, which would otherwise be singular. Its penalty part stays, and
  // Phi_k is still measured.
  void holdMultipliersAtZero(std::size_t k) { implied_.at(k) = true; }

  void measure(const double* z, Measures& out) const override;
  // augmented Lagrangian with a leading gap (none of it implied): its lambdas and mus are forces
  void spatialVectors(std::vector<SpatialVector>& out) const override;
  void eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  void rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  StageForm stageForm() const override { return StageForm::Own; }
  void stageLocal(const StageArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  // a residual-only evaluation takes the positions along the path once for all stages
  bool evaluatesStagesTogether() const override { return true; }
  void stageResiduals(const StageArgs& args, Workspace& ws, LocalSystem* out, Flows* flows) const override;

 private:
  static std::vector<int> collectDofs(const ConstraintSpec& spec);
  // The constrained positions (shift 0) or their velocities (shift = velocityShift) in z.
  ConstraintVector gather(const double* z, int shift) const;
  // lambda_k (0 for penalty and for an implied form, whose lambda is held at zero).
  double multiplier(const double* z, std::size_t k) const;
  bool augmented() const { return spec_.enforcement == Enforcement::AugmentedLagrangian; }
  // Whether lambda_k is an unknown of the step (augmented Lagrangian, and the form not implied).
  bool lambdaUnknown(std::size_t k) const { return augmented() && !implied_[k]; }
  // The stage form for stages firstStage .. firstStage + count - 1 into out[0 .. count - 1]: the
  // residuals, and with args.tangent (count 1) the derivative w.r.t. stage args.column.
  void addStages(const StageArgs& args, int firstStage, int count, LocalSystem* out) const;
  // addStages' parts: the step's path at the fine rule's points, form k's projections onto the
  // stages' test functions along it, and form k's rows of those stages (see the .cpp).
  struct StagePath;
  struct StageProjection;
  StagePath stagePath(const StageArgs& args, int firstStage, int count) const;
  StageProjection project(std::size_t k, const StageArgs& args, const StagePath& path, int count) const;
  void addFormRows(std::size_t k, const StageProjection& projection, const StageArgs& args, const StagePath& path,
                   int firstStage, int count, LocalSystem* out) const;
  ConstraintSpec spec_;
  int positionCount_;
  std::vector<bool> implied_;  // per form: multipliers held at zero
  // per coordinate, as bit masks over the coordinates: those sharing a form with it, and those
  // a form's Hessian couples to it
  std::uint32_t sharesAForm_[kMaxConstrainedDofs] = {}, sharesAHessian_[kMaxConstrainedDofs] = {};
};

}  // namespace mpx
