#pragma once
// One-step integrators on a compiled model: the EEM discrete-gradient scheme, its fourth-order
// energy-consistent Gauss collocation (eem4), and the standard implicit midpoint and trapezoidal
// rules (derived from the components' rate form), solved by Newton-Raphson with the consistent
// tangent, a backtracking line search on the residual and a bounded step cut-back.
#include "engine/core/model.hpp"
#include "engine/linear/assembler.hpp"
#include "engine/linear/condensed_solver.hpp"
#include "engine/linear/corotation.hpp"
#include "engine/stepping/loop_state.hpp"

#include <Eigen/Dense>

#include <array>
#include <cmath>

#include <string>
#include <vector>

namespace mpx {

// Eem4: two-stage Gauss collocation with energy-consistent stage gradients (docs/theory.md
// section 13), whose Newton unknowns are the values at both stages.
enum class Scheme { Eem, Eem4, Midpoint, Trapezoidal };

// The order of a scheme's local truncation error minus one (its global order).
inline int schemeOrder(Scheme scheme) { return scheme == Scheme::Eem4 ? 4 : 2; }

struct NewtonSettings {
  double incrementTolerance = 1e-10;  // max |dz_i| / (|z_i| + scale_i)
  double residualTolerance = 1e-8;    // max |R_i| / (sum of |terms| in R_i)
  int maxIterations = 25;
  int maxCutbacks = 6;  // each halves the step
  // Simplified Newton: keep a factorisation across iterations and steps while the increments
  // contract by at least this factor per iteration; refresh it (from the current tangent)
  // when they do not, when dt changes by more than a fifth or when the line search fails. The
  // iterates in between evaluate the residual alone. 0 (default): full Newton.
  double reuseContraction = 0.0;
  // Simplified Newton of a one-stage scheme factorises the symmetric part of a large condensed
  // tangent with CHOLMOD instead of the tangent with UMFPACK (engine/linear/cholmod_solver.hpp).
  // eem4's stage system is far from symmetric and keeps its LU.
  bool symmetricFactorisation = false;
  // Full Newton keeps its factorisation for the next iteration once the relative increment is
  // below this (0, the default: a fresh factorisation at every iteration whose residual has
  // not passed its test, and none while the factorisation in hand contracts the correction by
  // 0.003 or brings it within the tolerance; newton.cpp). At 1e-4 the
  // iterations stay the same in number and a fifth of the factorisations go on the L-block,
  // but the last iterate is less converged than after a fresh Newton step, and the stiff
  // thermal chain's energy balance ends at 1.6e-12 instead of 3e-14 (docs/performance.md).
  double reuseBelowIncrement = 0.0;
  // Simplified Newton (and IDA, through Metriplex's solver) turns a factorisation kept from an
  // earlier step with the scene's rotation since then (engine/linear/corotation.hpp).
  bool corotate = true;
  // Start each step that continues the last one from the polynomial through the last two to
  // four accepted states (eem4: its stages from the same polynomial plus the last step's stage
  // error) instead of from the old state.
  bool predictor = true;
};

struct StepOutcome {
  bool converged = false;
  int iterations = 0;      // Newton iterations, all sub-steps
  int cutbacks = 0;        // halvings needed
  int factorizations = 0;  // of the step tangent, all sub-steps
  Flows energy;            // crossed during the step (J)
  // what failed last (also when a cut-back then succeeded); a fixed buffer, so that a
  // recovered Newton failure does not allocate
  char failure[400] = "";
};

class Integrator {
 public:
  Integrator(const Model& model, Scheme scheme, NewtonSettings settings);

  // Advance state z at time t by dt into zNew, halving the step up to maxCutbacks times
  // when Newton fails. Allocates nothing. With `byComponent` (sized as
  // Assembler::componentFlows()), the step's flows per component go there as well.
  StepOutcome advance(const Eigen::VectorXd& z, double t, double dt, Eigen::VectorXd& zNew,
                      std::vector<Flows>* byComponent = nullptr);

  // Checkpoint: save the predictor into `out` and start the linear solver afresh
  // (engine/stepping/loop_state.hpp says why). Resume: take the predictor from a checkpoint,
  // with a fresh solver.
  void checkpoint(LoopState& out);
  void resume(const LoopState& saved);

  // Residual and tangent (without `tangent`: the residual alone) of the step from zOld with
  // Newton unknowns `unknowns`: the end state for one-stage schemes, the stage values one after
  // the other for eem4 (exposed for tangent tests).
  Assembler& evaluate(const Eigen::VectorXd& zOld, const Eigen::VectorXd& unknowns, double t, double dt,
                      bool tangent = true);
  // Newton unknowns of the step: the end state, or (eem4) stageCount() stage values.
  int stageCount() const { return rule_.stages; }
  Scheme scheme() const { return scheme_; }
  const CondensedSolver& linearSolver() const { return solver_; }

 private:
  // Midpoint or trapezoidal residual of the step from the components' rate form.
  void addRateForm(const Eigen::VectorXd& zOld, const Eigen::VectorXd& zNew, double t, double dt, bool tangent);
  // eem4: the stage rates and the end state of the stage polynomial, then its residual.
  void addStages(const Eigen::VectorXd& zOld, const Eigen::VectorXd& stages, double t, double dt, bool tangent);
  // z(t + dt) of the stage polynomial.
  void endOfStages(const Eigen::VectorXd& zOld, const Eigen::VectorXd& stages, Eigen::VectorXd& zEnd) const;
  bool advanceLevel(const Eigen::VectorXd& z, double t, double dt, int level, Eigen::VectorXd& zNew,
                    StepOutcome& outcome);
  // Newton from the initial guess in zNew (eem4: stages on the line from zOld to that guess,
  // or, if stagesGuessed, from the stage values already in stages_).
  bool solveStep(const Eigen::VectorXd& zOld, double t, double dt, Eigen::VectorXd& zNew, StepOutcome& outcome,
                 bool stagesGuessed = false);
  // True when a step from z at t continues the last accepted step.
  bool continuesLastStep(const Eigen::VectorXd& z, double t) const;
  // The polynomials of degrees predictorDegree_ through the newest past states, at `time`.
  void extrapolate(double time, Eigen::Ref<Eigen::VectorXd> out) const;
  // After a step that continued the past states: the degree whose polynomial came closest to
  // the state it reached (in the increment test's norm) predicts the next step, chosen for the
  // velocities and for the rest of the state apart.
  void choosePredictorDegree(double time, const Eigen::VectorXd& reached);

  // Newton on the step's unknowns (engine/stepping/newton.cpp), from the guess in `unknowns`
  // (zNew in the helpers below: the end state, or eem4's stage values).
  bool solveUnknowns(const Eigen::VectorXd& zOld, double t, double dt, Eigen::VectorXd& unknowns, StepOutcome& outcome);
  // What the correction from the factorisation in hand is worth once the residual passes its
  // test: none, one after which the next comes from the same factorisation, or the last.
  enum class HeldCorrection { None, Held, Last };
  // What one Newton solve carries from one iteration to the next.
  struct NewtonProgress {
    int iteration = 0;
    double residualNorm = INFINITY;              // relative, at the iterate
    double incrementNorm = INFINITY;             // of the correction that reached the iterate
    bool fullNewton = true;                      // not simplified: line-search trials assemble the tangent
    bool firstTrialResidualOnly = false;         // the first iteration's trials do not (the last solve factorised once)
    bool refresh = true;                         // the next correction needs a fresh factorisation
    bool tangentAtIterate = true;                // the evaluation at the iterate assembled its tangent
    bool tangentAtTrial = false;                 // the accepted trial's evaluation did
    bool heldOver = false;                       // a held correction went beyond the tolerance since the factorisation
    bool factorisedAtPrevious = false;           // the factorisation in hand is of the tangent at the iterate before
    bool lastApplied = false;                    // the correction that reached the iterate was taken as the last
    HeldCorrection held = HeldCorrection::None;  // this iteration's correction, if held
  };
  // Evaluate at the guess in zNew (at the old state where the guess's residual is not finite),
  // with the tangent where a fresh factorisation is due.
  NewtonProgress startNewton(const Eigen::VectorXd& zOld, double t, double dt, Eigen::VectorXd& zNew);
  // The residual norm relative to row scales taken from the tangent at zNew (after a
  // residual-only evaluation, from the last tangent evaluated).
  double rescaledResidualNorm(const Eigen::VectorXd& zNew, bool tangentAtIterate);
  // After an iteration: the increment within its tolerance (a tenth of it after a held-over
  // correction) or taken as the last, and the residual within its tolerance.
  bool newtonConverged(const NewtonProgress& progress) const;
  // What a correction of relative size heldNorm from the factorisation in hand is worth.
  HeldCorrection judgeHeldCorrection(double heldNorm, const NewtonProgress& progress) const;
  // Before a due refresh, once the residual passes its test: the correction from the
  // factorisation in hand is computed and judged, and `held` says whether it is applied (Held,
  // Last) or the refresh goes ahead (None).
  void holdCorrection(const Eigen::VectorXd& zNew, NewtonProgress& progress);
  // The correction (from a fresh factorisation where one is due, unless one is held), and a
  // backtracking search along it from zNew until the residual is finite and decreases (a full
  // step near the solution, where the residual is already at round-off level); if no step
  // decreases it, a kept factorisation is refreshed, then the reused pivots are replaced. The
  // step taken (the trial left in trial_), or 0 and the failure's reason.
  double searchAlongCorrection(const Eigen::VectorXd& zOld, double t, double dt, const Eigen::VectorXd& zNew,
                               NewtonProgress& progress, StepOutcome& outcome, const char*& failure);
  // Move zNew to the accepted trial and decide whether the next correction needs a refresh.
  void acceptTrial(double step, Eigen::VectorXd& zNew, NewtonProgress& progress);
  // Record `what` failed, where, and which component's residual went non-finite, if any; false.
  bool failNewton(const char* what, const NewtonProgress& progress, StepOutcome& outcome);
  // Factorise the tangent of the last evaluation that assembled one, for the step from zOld;
  // false if singular.
  bool refactorize(const Eigen::VectorXd& zOld, double dt, bool repivot, StepOutcome& outcome);
  // increment_ = the Newton correction for `residual` from the factorisation in hand, turned
  // with the scene since it was made.
  void correct(const Eigen::VectorXd& residual);
  // max_i |increment_i| / (|z_i| + scale_i), the increment test's norm (multipliers left out)
  double relativeNorm(const Eigen::VectorXd& increment, const Eigen::VectorXd& z) const;
  // Largest step 1, 1/2, ... along increment_ from zNew that decreases the residual (left
  // evaluated at zNew + step increment_ in trial_, with the tangent if asked); 0 if none does.
  double lineSearch(const Eigen::VectorXd& zOld, double t, double dt, const Eigen::VectorXd& zNew, double residualNorm,
                    bool tangent);

  const Model& model_;
  Scheme scheme_;
  NewtonSettings settings_;
  CollocationRule rule_;  // eem4's; one stage otherwise
  Assembler assembler_;
  CondensedSolver solver_;
  Corotation corotation_;
  Eigen::VectorXd turnedResidual_;
  Workspace workspace_;
  Eigen::VectorXd zMid_, zDot_, increment_, trial_, stateScale_;
  // per Newton unknown: its dof's scale, and the same with multipliers at infinity (multipliers
  // have no natural scale; their rows' residual, the constraints, judges them)
  Eigen::VectorXd unknownScale_, incrementScale_;
  Eigen::VectorXd stages_, stageRates_, stageEnd_;  // eem4
  // eem4's stage predictor: the polynomial's values at this step's stages, and the last step's
  // stages minus that step's (over stageMissDt_), the stage error the polynomial does not see
  Eigen::VectorXd stagePrediction_, stageMiss_;
  bool stagesPredicted_ = false, stageMissKept_ = false;
  double stageMissDt_ = 0.0;
  std::vector<Eigen::VectorXd> halfState_;  // one midpoint state per cut-back level
  // simplified Newton: the step size the factorisation belongs to (0: none held)
  double factorizedDt_ = 0.0;
  bool oneFactorisationSufficed_ = false;  // the last Newton solve factorised once
  // predictor: the last accepted states, newest first, at their times; pastCount_ of them
  // follow each other step by step (two or more: a step from pastStates_[0] continues them)
  static constexpr int kPastStates = 4;
  std::array<Eigen::VectorXd, kPastStates> pastStates_;
  std::array<double, kPastStates> pastTimes_{};
  int pastCount_ = 0;
  // the degrees of the polynomials through the past states (below pastCount_), for the velocities
  // and for the rest of the state: across a mechanism's turning constraints the one-stage schemes
  // leave the velocities a component that flips its sign from step to step (the positions'
  // increments are the velocities' step means), which a higher degree mispredicts by more
  static constexpr int kVelocities = 0, kRestOfState = 1;
  std::array<int, 2> predictorDegree_{1, 1};
  bool motionResolved_ = false;                // the line came within kResolvedMiss of the last state reached
  std::vector<Flows>* byComponent_ = nullptr;  // of the advance under way, if asked for
};

}  // namespace mpx
