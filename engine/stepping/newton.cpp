// Newton-Raphson on one step's unknowns (declared in integrator.hpp): full or simplified
// Newton, a correction held from the factorisation in hand once the residual passes its test,
// a backtracking line search, and refreshed or repivoted factorisations before a failure.
#include "engine/stepping/integrator.hpp"

#include <cmath>
#include <cstdio>

namespace mpx {

namespace {
// Backtracking gives up (and the step is cut back) below this fraction of a Newton step.
constexpr double kSmallestLineSearchStep = 1.0 / 1024;
// Simplified Newton keeps a factorisation across step-size changes up to this fraction (the
// contraction check refreshes it when the old step's tangent no longer contracts well).
constexpr double kReusableStepChange = 0.2;
// Newton goes on with the factorisation in hand while its correction is at most this fraction
// of the increment before it: a fresh factorisation costs several residuals.
constexpr double kHeldContraction = 0.003;
// A factorisation held over more than one correction contracts linearly, not quadratically: its
// last increment must be this fraction of the increment tolerance to leave the iterate as close
// to the solution as a Newton step within the tolerance does (the two thermo-springs' eem4
// balance per step stays at 6e-15; within the tolerance alone it reached 1.3e-14).
constexpr double kHeldOverTolerance = 0.1;

// After a Newton correction within kRoundOffBand^2 times the increment tolerance (1e-8), the
// correction from the same factorisation at the next iterate is the last one up to kRoundOffBand
// times the tolerance: as a correction it leaves an error of the order of the product of the two
// (1e-17 relative), and as round-off no further correction removes it. eem4's stage gradients
// divide psi's change over a step by the stage rates, so their residual carries up to 1e-11
// relative round-off where the arguments barely move (engine/core/stage_gradient.hpp), and
// corrections there wander at 1e-10-3e-10, around the tolerance: the two thermo-springs from
// t = 8000 to 16000 took up to 5 iterations and 4 factorisations per step instead of 2 and 1.
constexpr double kRoundOffBand = 10.0;
}  // namespace

// What the correction from the factorisation in hand is worth once the residual passes its test
// (a fresh factorisation costs several residuals, so it is tried first). A correction within the
// increment tolerance is the last, and so is one within kRoundOffBand of it from a factorisation
// made at the iterate before, after a correction within kRoundOffBand^2 of it; one that
// contracts by kHeldContraction on the increment before it is applied too, and the next
// correction comes from the same factorisation (held over), which from then on must contract by
// as much to be kept. Otherwise none is held and the factorisation is refreshed.
Integrator::HeldCorrection Integrator::judgeHeldCorrection(double heldNorm, const NewtonProgress& progress) const {
  const double tolerance = settings_.incrementTolerance;
  if ((!progress.heldOver && heldNorm <= tolerance) ||
      (progress.factorisedAtPrevious && heldNorm <= kRoundOffBand * tolerance &&
       progress.incrementNorm <= kRoundOffBand * kRoundOffBand * tolerance))
    return HeldCorrection::Last;
  return heldNorm <= kHeldContraction * progress.incrementNorm ? HeldCorrection::Held : HeldCorrection::None;
}

bool Integrator::solveUnknowns(const Eigen::VectorXd& zOld, double t, double dt, Eigen::VectorXd& zNew,
                               StepOutcome& outcome) {
  // a failure names the component and dof whose residual went non-finite in this step, if any
  assembler_.forgetNonFinite();
  const int factorisationsBefore = outcome.factorizations;
  NewtonProgress progress = startNewton(zOld, t, dt, zNew);
  if (!std::isfinite(progress.residualNorm))
    return failNewton("non-finite residual at the start of the step", progress, outcome);
  for (;; ++progress.iteration) {
    if (newtonConverged(progress)) {
      oneFactorisationSufficed_ = outcome.factorizations - factorisationsBefore == 1;
      outcome.energy += assembler_.flows() * dt;
      if (byComponent_)
        for (std::size_t c = 0; c < byComponent_->size(); ++c)
          (*byComponent_)[c] += assembler_.componentFlows()[c] * dt;
      return true;
    }
    if (progress.iteration == settings_.maxIterations) return failNewton("Newton did not converge", progress, outcome);
    holdCorrection(zNew, progress);
    const char* failure = nullptr;
    const double step = searchAlongCorrection(zOld, t, dt, zNew, progress, outcome, failure);
    if (step == 0.0) return failNewton(failure, progress, outcome);
    acceptTrial(step, zNew, progress);
    ++outcome.iterations;
  }
}

Integrator::NewtonProgress Integrator::startNewton(const Eigen::VectorXd& zOld, double t, double dt,
                                                   Eigen::VectorXd& zNew) {
  NewtonProgress progress;
  // Simplified Newton's iterates need the residual alone while the factorisation is kept; the
  // tangent is evaluated where it is factorised.
  progress.fullNewton = settings_.reuseContraction <= 0.0;
  // Full Newton: where the last solve needed a single factorisation, the first iterate is
  // probably the last to need a tangent (the next correction comes from the factorisation in
  // hand), so its trial evaluates the residual alone; the tangent follows if it is needed after all
  progress.firstTrialResidualOnly = oneFactorisationSufficed_;
  progress.refresh = progress.fullNewton || !(std::abs(dt - factorizedDt_) <= kReusableStepChange * factorizedDt_);
  // a factorisation kept from an earlier step turns with the scene to this step's start
  if (!progress.refresh && settings_.corotate) corotation_.follow(zOld);
  progress.tangentAtIterate = progress.refresh;
  // a predictor whose residual is not finite is no start: begin from the old state
  evaluate(zOld, zNew, t, dt, progress.tangentAtIterate);
  progress.residualNorm = rescaledResidualNorm(zNew, progress.tangentAtIterate);
  if (!std::isfinite(progress.residualNorm)) {
    zNew = zOld.replicate(rule_.stages, 1);
    evaluate(zOld, zNew, t, dt, progress.tangentAtIterate);
    progress.residualNorm = rescaledResidualNorm(zNew, progress.tangentAtIterate);
  }
  return progress;
}

double Integrator::rescaledResidualNorm(const Eigen::VectorXd& zNew, bool tangentAtIterate) {
  stateScale_ = zNew.cwiseAbs() + unknownScale_;
  if (tangentAtIterate) assembler_.updateRowScale(stateScale_);
  return assembler_.relativeResidualNorm();
}

bool Integrator::newtonConverged(const NewtonProgress& progress) const {
  const double incrementTolerance = (progress.heldOver ? kHeldOverTolerance : 1.0) * settings_.incrementTolerance;
  return progress.iteration > 0 && (progress.incrementNorm <= incrementTolerance || progress.lastApplied) &&
         progress.residualNorm <= settings_.residualTolerance;
}

void Integrator::holdCorrection(const Eigen::VectorXd& zNew, NewtonProgress& progress) {
  progress.held = HeldCorrection::None;
  if (!progress.refresh || progress.iteration == 0 || progress.residualNorm > settings_.residualTolerance) return;
  correct(assembler_.residual());
  progress.held = judgeHeldCorrection(relativeNorm(increment_, zNew), progress);
  progress.heldOver = progress.heldOver || progress.held == HeldCorrection::Held;
  progress.refresh = progress.held == HeldCorrection::None;
}

double Integrator::searchAlongCorrection(const Eigen::VectorXd& zOld, double t, double dt, const Eigen::VectorXd& zNew,
                                         NewtonProgress& progress, StepOutcome& outcome, const char*& failure) {
  for (bool repivot = false;;) {
    if (progress.refresh && !progress.tangentAtIterate) {
      progress.tangentAtIterate = true;
      evaluate(zOld, zNew, t, dt);
      progress.residualNorm = rescaledResidualNorm(zNew, true);
    }
    if (progress.refresh && !refactorize(zOld, dt, repivot, outcome)) {
      failure = "singular tangent";
      return 0.0;
    }
    progress.heldOver = progress.heldOver && !progress.refresh;
    if (progress.held == HeldCorrection::None) correct(assembler_.residual());
    progress.tangentAtTrial = progress.fullNewton && progress.held == HeldCorrection::None &&
                              !(progress.iteration == 0 && progress.firstTrialResidualOnly);
    const double step = lineSearch(zOld, t, dt, zNew, progress.residualNorm, progress.tangentAtTrial);
    if (step > 0.0) return step;
    if (progress.refresh && repivot) {
      failure = "no decrease of the residual along the Newton direction";
      return 0.0;
    }
    repivot = progress.refresh;
    progress.refresh = true;
    progress.held = HeldCorrection::None;
    progress.tangentAtIterate = false;  // the trials replaced the evaluation at zNew
  }
}

void Integrator::acceptTrial(double step, Eigen::VectorXd& zNew, NewtonProgress& progress) {
  zNew.swap(trial_);
  const bool factorisedNow = progress.refresh;
  progress.tangentAtIterate = progress.tangentAtTrial;
  const double previousIncrementNorm = progress.incrementNorm;
  progress.incrementNorm = step * relativeNorm(increment_, zNew);
  progress.residualNorm = rescaledResidualNorm(zNew, progress.tangentAtIterate);
  // (a factorisation of the tangent's symmetric part contracts linearly even when fresh; a held
  // correction never comes with a refresh: holdCorrection sets refresh = (held == None), and a
  // retried search resets both)
  progress.factorisedAtPrevious = factorisedNow && step == 1.0 && solver_.factorisesTheTangent();
  progress.lastApplied = progress.held == HeldCorrection::Last;
  // keep the factorisation while the iteration contracts well (or has converged); full Newton
  // keeps it too once the increment is small: a tangent taken that close to the solution
  // contracts the next increment about as much as a fresh one (by about its own size)
  const bool closeEnough = progress.incrementNorm <= settings_.reuseBelowIncrement;
  progress.refresh = progress.fullNewton
                         ? !closeEnough
                         : progress.incrementNorm > settings_.incrementTolerance &&
                               !(progress.incrementNorm <= settings_.reuseContraction * previousIncrementNorm);
}

bool Integrator::failNewton(const char* what, const NewtonProgress& progress, StepOutcome& outcome) {
  char note[200] = "";
  if (assembler_.describeNonFinite(model_, note + 2, sizeof note - 2) > 0) note[0] = ';', note[1] = ' ';
  std::snprintf(outcome.failure, sizeof outcome.failure, "%s (Newton iteration %d, increment %.3g, residual %.3g%s)",
                what, progress.iteration, progress.incrementNorm, progress.residualNorm, note);
  return false;
}

double Integrator::relativeNorm(const Eigen::VectorXd& increment, const Eigen::VectorXd& z) const {
  return (increment.array().abs() / (z.array().abs() + incrementScale_.array())).maxCoeff();
}

bool Integrator::refactorize(const Eigen::VectorXd& zOld, double dt, bool repivot, StepOutcome& outcome) {
  factorizedDt_ = 0.0;
  ++outcome.factorizations;
  if (!solver_.factorize(assembler_.tangent(), repivot)) return false;
  factorizedDt_ = dt;
  corotation_.anchor(zOld);
  return true;
}

void Integrator::correct(const Eigen::VectorXd& residual) {
  corotation_.solve(solver_, residual, turnedResidual_, increment_);
}

double Integrator::lineSearch(const Eigen::VectorXd& zOld, double t, double dt, const Eigen::VectorXd& zNew,
                              double residualNorm, bool tangent) {
  for (double step = 1.0; step >= kSmallestLineSearchStep; step *= 0.5) {
    trial_ = zNew + step * increment_;
    evaluate(zOld, trial_, t, dt, tangent);
    const double trialNorm = assembler_.relativeResidualNorm();
    if (trialNorm <= (1.0 - 1e-4 * step) * residualNorm ||
        (std::isfinite(trialNorm) && residualNorm <= settings_.residualTolerance))
      return step;
  }
  return 0.0;
}

}  // namespace mpx
