#include "engine/stepping/integrator.hpp"

#include "engine/core/collocation_rule.hpp"

#include <algorithm>
#include <array>
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

// What the correction from the factorisation in hand is worth once the residual passes its test
// (a fresh factorisation costs several residuals, so it is tried first). A correction within the
// increment tolerance is the last, and so is one within kRoundOffBand of it from a factorisation
// made at the iterate before, after a correction within kRoundOffBand^2 of it; one that
// contracts by kHeldContraction on the increment before it is applied too, and the next
// correction comes from the same factorisation (held over), which from then on must contract by
// as much to be kept. Otherwise the factorisation is refreshed.
enum class HeldCorrection { Refresh, Held, Last };
HeldCorrection judgeHeldCorrection(double heldNorm, double incrementNorm, double tolerance, bool heldOver,
                                   bool factorisedAtPrevious) {
  if ((!heldOver && heldNorm <= tolerance) || (factorisedAtPrevious && heldNorm <= kRoundOffBand * tolerance &&
                                               incrementNorm <= kRoundOffBand * kRoundOffBand * tolerance))
    return HeldCorrection::Last;
  return heldNorm <= kHeldContraction * incrementNorm ? HeldCorrection::Held : HeldCorrection::Refresh;
}

// The components' local form each scheme evaluates.
Component::LocalForm localForm(Scheme scheme) {
  if (scheme == Scheme::Eem) return Component::LocalForm::Step;
  return scheme == Scheme::Eem4 ? Component::LocalForm::Stages : Component::LocalForm::Rate;
}
}  // namespace

Integrator::Integrator(const Model& model, Scheme scheme, NewtonSettings settings)
    : model_(model),
      scheme_(scheme),
      settings_(settings),
      rule_(gaussCollocation(scheme == Scheme::Eem4 ? 2 : 1)),
      assembler_(model, localForm(scheme), rule_.stages),
      solver_(model.layout(), assembler_.tangent(), settings.symmetricFactorisation && rule_.stages == 1),
      corotation_(model, rule_.stages),
      turnedResidual_(rule_.stages * model.layout().total()),
      workspace_(model.makeWorkspace()),
      zMid_(model.layout().total()),
      zDot_(model.layout().total()),
      increment_(rule_.stages * model.layout().total()),
      trial_(rule_.stages * model.layout().total()),
      halfState_(settings.maxCutbacks + 1, Eigen::VectorXd(model.layout().total())) {
  for (auto& state : pastStates_) state.resize(model.layout().total());
  pastTimes_.fill(NAN);  // no past step: the first step starts from the old state
  const int n = model.layout().total(), withScale = model.layout().offset(Block::Multiplier);
  unknownScale_ = model.dofScale().replicate(rule_.stages, 1);
  incrementScale_ = unknownScale_;
  for (int l = 0; l < rule_.stages; ++l)
    incrementScale_.segment(l * n + withScale, n - withScale).setConstant(INFINITY);
  if (scheme == Scheme::Eem4) {
    stages_.resize(rule_.stages * n);
    stagePrediction_.resize(rule_.stages * n);
    stageMiss_.resize(rule_.stages * n);
    stageRates_.resize(rule_.stages * n);
    stageEnd_.resize(n);
  }
}

Assembler& Integrator::evaluate(const Eigen::VectorXd& zOld, const Eigen::VectorXd& zNew, double t, double dt,
                                bool tangent) {
  assembler_.clear(tangent);
  if (scheme_ == Scheme::Eem4) {
    addStages(zOld, zNew, t, dt, tangent);
    return assembler_;
  }
  if (scheme_ == Scheme::Eem) {
    assembler_.addStep(model_, workspace_, {zOld.data(), zNew.data(), t, dt, tangent});
  } else {
    addRateForm(zOld, zNew, t, dt, tangent);
  }
  assembler_.imposeStepMotions(model_, zOld.data(), zNew.data(), t, dt);
  return assembler_;
}

void Integrator::addRateForm(const Eigen::VectorXd& zOld, const Eigen::VectorXd& zNew, double t, double dt,
                             bool tangent) {
  zDot_ = (zNew - zOld) / dt;
  // the tangent's coefficients (alpha = beta = 0: the residual alone)
  const double rateCoefficient = tangent ? 1.0 / dt : 0.0, stateCoefficient = tangent ? 1.0 : 0.0;
  // midpoint: F(t + dt/2, (z + z')/2, (z' - z)/dt)
  if (scheme_ == Scheme::Midpoint) {
    zMid_ = 0.5 * (zOld + zNew);
    assembler_.addRate(model_, workspace_,
                       {zMid_.data(), zDot_.data(), t + 0.5 * dt, 0.5 * stateCoefficient, rateCoefficient}, 1.0);
    return;
  }
  // trapezoidal: mean of F at both end points with the same (z' - z)/dt
  assembler_.addRate(model_, workspace_, {zOld.data(), zDot_.data(), t, 0.0, rateCoefficient}, 0.5);
  assembler_.addRate(model_, workspace_, {zNew.data(), zDot_.data(), t + dt, stateCoefficient, rateCoefficient}, 0.5);
}

void Integrator::addStages(const Eigen::VectorXd& zOld, const Eigen::VectorXd& stages, double t, double dt,
                           bool tangent) {
  const int n = static_cast<int>(zOld.size());
  const double* state[CollocationRule::kMostStages] = {};
  const double* rate[CollocationRule::kMostStages] = {};
  endOfStages(zOld, stages, stageEnd_);
  for (int l = 0; l < rule_.stages; ++l) {
    auto stageRate = stageRates_.segment(l * n, n);
    // from the stages' increments over zOld (the rate coefficients sum to zero): a rate then
    // carries the round-off of the increments, not of the values
    stageRate.setZero();
    for (int j = 0; j < rule_.stages; ++j) stageRate += (rule_.rate[l][j + 1] / dt) * (stages.segment(j * n, n) - zOld);
    state[l] = stages.data() + l * n;
    rate[l] = stageRates_.data() + l * n;
  }
  const StageArgs args{&rule_, zOld.data(), stageEnd_.data(), state, rate, t, dt, 0, 0, tangent};
  assembler_.addStages(model_, workspace_, args);
  assembler_.imposeStageMotions(model_, args);
}

bool Integrator::solveStep(const Eigen::VectorXd& zOld, double t, double dt, Eigen::VectorXd& zNew,
                           StepOutcome& outcome, bool stagesGuessed) {
  if (rule_.stages == 1) return solveUnknowns(zOld, t, dt, zNew, outcome);
  // the stages start on the line from the old state to the guessed end state, unless guessed
  const int n = static_cast<int>(zOld.size());
  if (!stagesGuessed)
    for (int l = 0; l < rule_.stages; ++l) stages_.segment(l * n, n) = zOld + rule_.node[l] * (zNew - zOld);
  if (!solveUnknowns(zOld, t, dt, stages_, outcome)) return false;
  endOfStages(zOld, stages_, zNew);
  return true;
}

void Integrator::endOfStages(const Eigen::VectorXd& zOld, const Eigen::VectorXd& stages, Eigen::VectorXd& zEnd) const {
  const int n = static_cast<int>(zOld.size());
  // as the rates, from the increments (the end coefficients sum to one)
  zEnd = zOld;
  for (int l = 0; l < rule_.stages; ++l) zEnd += rule_.end[l + 1] * (stages.segment(l * n, n) - zOld);
}

bool Integrator::solveUnknowns(const Eigen::VectorXd& zOld, double t, double dt, Eigen::VectorXd& zNew,
                               StepOutcome& outcome) {
  // a failure names the component and dof whose residual went non-finite in this step, if any
  assembler_.forgetNonFinite();
  auto fail = [&](const char* what, int iteration, double incrementNorm, double residualNorm) {
    char note[200] = "";
    if (assembler_.describeNonFinite(model_, note + 2, sizeof note - 2) > 0) note[0] = ';', note[1] = ' ';
    std::snprintf(outcome.failure, sizeof outcome.failure, "%s (Newton iteration %d, increment %.3g, residual %.3g%s)",
                  what, iteration, incrementNorm, residualNorm, note);
    return false;
  };
  // Simplified Newton's iterates need the residual alone while the factorisation is kept; the
  // tangent is evaluated where it is factorised.
  const bool simplified = settings_.reuseContraction > 0.0;
  // Full Newton: where the last solve needed a single factorisation, the first iterate is
  // probably the last to need a tangent (the next correction comes from the factorisation in
  // hand), so its trial evaluates the residual alone; the tangent follows if it is needed after all
  const bool tangentLikelyDone = oneFactorisationSufficed_;
  const int factorisationsBefore = outcome.factorizations;
  bool refresh = !simplified || !(std::abs(dt - factorizedDt_) <= kReusableStepChange * factorizedDt_);
  // a factorisation kept from an earlier step turns with the scene to this step's start
  if (!refresh && settings_.corotate) corotation_.follow(zOld);
  bool tangentAtIterate = refresh;
  // the residual norm relative to row scales taken from the tangent at the current iterate
  // (after a residual-only evaluation, from the last tangent evaluated)
  auto rescaledNorm = [&](Assembler& system) {
    stateScale_ = zNew.cwiseAbs() + unknownScale_;
    if (tangentAtIterate) system.updateRowScale(stateScale_);
    return system.relativeResidualNorm();
  };

  // a predictor whose residual is not finite is no start: begin from the old state
  Assembler& system = evaluate(zOld, zNew, t, dt, tangentAtIterate);
  double residualNorm = rescaledNorm(system);
  if (!std::isfinite(residualNorm)) {
    zNew = zOld.replicate(rule_.stages, 1);
    evaluate(zOld, zNew, t, dt, tangentAtIterate);
    residualNorm = rescaledNorm(system);
  }
  double incrementNorm = INFINITY;
  // whether the factorisation in hand has given a correction beyond the tolerance since it was made
  bool heldOver = false;
  // whether the factorisation in hand is of the tangent at the iterate before the current one,
  // and whether the correction just applied was taken as the last
  bool factorisedAtPrevious = false, lastApplied = false;
  if (!std::isfinite(residualNorm)) return fail("non-finite residual at the start of the step", 0, 0.0, residualNorm);
  for (int iteration = 0;; ++iteration) {
    const double incrementTolerance = (heldOver ? kHeldOverTolerance : 1.0) * settings_.incrementTolerance;
    if (iteration > 0 && (incrementNorm <= incrementTolerance || lastApplied) &&
        residualNorm <= settings_.residualTolerance) {
      oneFactorisationSufficed_ = outcome.factorizations - factorisationsBefore == 1;
      outcome.energy += system.flows() * dt;
      if (byComponent_)
        for (std::size_t c = 0; c < byComponent_->size(); ++c) (*byComponent_)[c] += system.componentFlows()[c] * dt;
      return true;
    }
    if (iteration == settings_.maxIterations)
      return fail("Newton did not converge", iteration, incrementNorm, residualNorm);
    // once the residual passes its test, the factorisation in hand may give the next correction
    // (judgeHeldCorrection), which is then applied with a residual-only evaluation
    bool held = false, last = false;
    if (refresh && iteration > 0 && residualNorm <= settings_.residualTolerance) {
      correct(system.residual());
      const HeldCorrection worth = judgeHeldCorrection(relativeNorm(increment_, zNew), incrementNorm,
                                                       settings_.incrementTolerance, heldOver, factorisedAtPrevious);
      last = worth == HeldCorrection::Last;
      held = worth != HeldCorrection::Refresh;
      heldOver = heldOver || worth == HeldCorrection::Held;
      refresh = !held;
    }
    // backtrack along the Newton direction until the residual is finite and decreases (a
    // full step near the solution, where the residual is already at round-off level); if no
    // step decreases it, a kept factorisation is refreshed, then the reused pivots are
    // replaced, before the step counts as failed
    double step = 1.0;
    bool tangentAtTrial = false;
    for (bool repivot = false;;) {
      if (refresh && !tangentAtIterate) {
        tangentAtIterate = true;
        evaluate(zOld, zNew, t, dt);
        residualNorm = rescaledNorm(system);
      }
      if (refresh && !refactorize(zOld, dt, repivot, outcome))
        return fail("singular tangent", iteration, incrementNorm, residualNorm);
      heldOver = heldOver && !refresh;
      if (!held) correct(system.residual());
      tangentAtTrial = !simplified && !held && !(iteration == 0 && tangentLikelyDone);
      step = lineSearch(zOld, t, dt, zNew, residualNorm, tangentAtTrial);
      if (step > 0.0) break;
      if (refresh && repivot)
        return fail("no decrease of the residual along the Newton direction", iteration, incrementNorm, residualNorm);
      repivot = refresh;
      refresh = true;
      held = last = false;
      tangentAtIterate = false;  // the trials replaced the evaluation at zNew
    }
    zNew.swap(trial_);
    tangentAtIterate = tangentAtTrial;
    ++outcome.iterations;
    const double previousIncrementNorm = incrementNorm;
    incrementNorm = step * relativeNorm(increment_, zNew);
    residualNorm = rescaledNorm(system);
    // (a factorisation of the tangent's symmetric part contracts linearly even when fresh)
    factorisedAtPrevious = refresh && !held && step == 1.0 && solver_.factorisesTheTangent();
    lastApplied = last;
    // keep the factorisation while the iteration contracts well (or has converged); full Newton
    // keeps it too once the increment is small: a tangent taken that close to the solution
    // contracts the next increment about as much as a fresh one (by about its own size)
    const bool closeEnough = incrementNorm <= settings_.reuseBelowIncrement;
    refresh = settings_.reuseContraction <= 0.0
                  ? !closeEnough
                  : incrementNorm > settings_.incrementTolerance &&
                        !(incrementNorm <= settings_.reuseContraction * previousIncrementNorm);
  }
}

double Integrator::relativeNorm(const Eigen::VectorXd& increment, const Eigen::VectorXd& z) const {
  return (increment.array().abs() / (z.array().abs() + incrementScale_.array())).maxCoeff();
}

bool Integrator::continuesLastStep(const Eigen::VectorXd& z, double t) const {
  return pastCount_ >= 2 && std::abs(t - pastTimes_[0]) <= 1e-12 * (std::abs(t) + pastTimes_[0] - pastTimes_[1]) &&
         z == pastStates_[0];
}

// The weights of the past states in the polynomial of degree `degree` through the newest
// degree + 1 of them, at `time`: p(time) = sum_k weight_k z_k. The weights cost O(degree^2)
// once, so each state entry costs degree + 1 multiply-adds.
namespace {
template <std::size_t N>
std::array<double, N> lagrangeWeights(const std::array<double, N>& times, int degree, double time) {
  std::array<double, N> weight{};
  for (int k = 0; k <= degree; ++k) weight[k] = lagrangeBasis(times, degree + 1, k, time);
  return weight;
}
}  // namespace

void Integrator::extrapolate(double time, Eigen::Ref<Eigen::VectorXd> out) const {
  const Layout& layout = model_.layout();
  const int velocities = layout.offset(Block::Velocity), velocityCount = layout.size(Block::Velocity);
  std::array<std::array<double, kPastStates>, 2> weight{};
  for (int part : {kVelocities, kRestOfState}) weight[part] = lagrangeWeights(pastTimes_, predictorDegree_[part], time);
  auto predict = [&](int first, int count, int part) {
    auto values = out.segment(first, count);
    values = weight[part][0] * pastStates_[0].segment(first, count);
    for (int k = 1; k <= predictorDegree_[part]; ++k) values += weight[part][k] * pastStates_[k].segment(first, count);
  };
  // one pass over the state where both parts take the same degree
  if (predictorDegree_[kVelocities] == predictorDegree_[kRestOfState]) {
    predict(0, layout.total(), kRestOfState);
    return;
  }
  predict(0, velocities, kRestOfState);
  predict(velocities, velocityCount, kVelocities);
  predict(velocities + velocityCount, layout.total() - velocities - velocityCount, kRestOfState);
}

// A degree above one is chosen only where the line came within this of the last state reached:
// where the steps resolve the motion. The L-block's 70 rad/s mode at dt 0.1 (line misses of
// 0.5-0.75) mispredicts every degree, and the higher ones by more.
constexpr double kResolvedMiss = 0.2;

void Integrator::choosePredictorDegree(double time, const Eigen::VectorXd& reached) {
  // each degree's miss in the increment test's norm, for the velocities and for the rest of the
  // state, from one pass over the past states
  const int highest = pastCount_ - 1;
  std::array<std::array<double, kPastStates>, kPastStates> weight{};
  for (int k = 1; k <= highest; ++k) weight[k] = lagrangeWeights(pastTimes_, k, time);
  const Layout& layout = model_.layout();
  const Eigen::Index velocities = layout.offset(Block::Velocity),
                     afterVelocities = velocities + layout.size(Block::Velocity);
  double miss[2][kPastStates] = {};
  for (Eigen::Index i = 0; i < reached.size(); ++i) {
    const double scale = 1.0 / (std::abs(reached[i]) + incrementScale_[i]);
    double* partMiss = miss[i >= velocities && i < afterVelocities ? kVelocities : kRestOfState];
    for (int k = 1; k <= highest; ++k) {
      double value = 0.0;
      for (int j = 0; j <= k; ++j) value += weight[k][j] * pastStates_[j][i];
      partMiss[k] = std::max(partMiss[k], std::abs(reached[i] - value) * scale);
    }
  }
  predictorDegree_.fill(1);
  motionResolved_ = std::max(miss[kVelocities][1], miss[kRestOfState][1]) <= kResolvedMiss;
  if (!motionResolved_) return;
  for (int part : {kVelocities, kRestOfState})
    for (int k = 2; k <= highest; ++k)
      if (miss[part][k] < miss[part][predictorDegree_[part]]) predictorDegree_[part] = k;
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

bool Integrator::advanceLevel(const Eigen::VectorXd& z, double t, double dt, int level, Eigen::VectorXd& zNew,
                              StepOutcome& outcome) {
  // the first attempt of a step that continues the last one starts from the extrapolation;
  // if Newton fails from there, it tries again from the old state before cutting back
  const bool continues = level == 0 && settings_.predictor && continuesLastStep(z, t);
  if (continues) {
    const int n = static_cast<int>(z.size());
    if (rule_.stages > 1) {
      for (int l = 0; l < rule_.stages; ++l) extrapolate(t + rule_.node[l] * dt, stages_.segment(l * n, n));
      // the polynomial runs through step ends, accurate to dt^4, but Newton's target is the Gauss
      // stages, which miss the trajectory by dt^3: where the steps resolve the motion, the last
      // step's miss, scaled to this step, is added
      stagePrediction_ = stages_;
      stagesPredicted_ = true;
      if (stageMissKept_ && motionResolved_) stages_ += std::pow(dt / stageMissDt_, 3) * stageMiss_;
    } else {
      extrapolate(t + dt, zNew);
    }
    if (solveStep(z, t, dt, zNew, outcome, rule_.stages > 1)) return true;
    factorizedDt_ = 0.0;
  }
  zNew = z;
  if (solveStep(z, t, dt, zNew, outcome)) return true;
  factorizedDt_ = 0.0;  // what failed here is not to be reused by the cut-back
  if (level == settings_.maxCutbacks) return false;
  // cut back: two half steps through an intermediate state of this level
  ++outcome.cutbacks;
  Eigen::VectorXd& half = halfState_[level];
  return advanceLevel(z, t, 0.5 * dt, level + 1, half, outcome) &&
         advanceLevel(half, t + 0.5 * dt, 0.5 * dt, level + 1, zNew, outcome);
}

StepOutcome Integrator::advance(const Eigen::VectorXd& z, double t, double dt, Eigen::VectorXd& zNew,
                                std::vector<Flows>* byComponent) {
  StepOutcome outcome;
  byComponent_ = byComponent;
  assembler_.keepComponentFlows(byComponent != nullptr);
  if (byComponent) std::fill(byComponent->begin(), byComponent->end(), Flows{});
  stagesPredicted_ = false;
  outcome.converged = advanceLevel(z, t, dt, 0, zNew, outcome);
  if (outcome.converged) {
    // eem4: the stage error of a step taken whole from a prediction
    stageMissKept_ = stagesPredicted_ && outcome.cutbacks == 0;
    if (stageMissKept_) {
      stageMiss_ = stages_ - stagePrediction_;
      stageMissDt_ = dt;
    }
    // the past states: the new one first, after those it continues
    if (continuesLastStep(z, t)) {
      choosePredictorDegree(t + dt, zNew);
      std::rotate(pastStates_.rbegin(), pastStates_.rbegin() + 1, pastStates_.rend());
      std::rotate(pastTimes_.rbegin(), pastTimes_.rbegin() + 1, pastTimes_.rend());
      pastCount_ = std::min(pastCount_ + 1, kPastStates);
    } else {
      pastStates_[1] = z;
      pastTimes_[1] = t;
      pastCount_ = 2;
      predictorDegree_.fill(1);
      motionResolved_ = false;
    }
    pastStates_[0] = zNew;
    pastTimes_[0] = t + dt;
  }
  return outcome;
}

void Integrator::checkpoint(LoopState& out) {
  out.predictorStart = pastStates_[1];
  out.predictorEnd = pastStates_[0];
  out.predictorTime = pastTimes_[1];
  out.predictorDt = pastTimes_[0] - pastTimes_[1];
  solver_.startAfresh();
  factorizedDt_ = 0.0;
  // only the last step is saved: the run that writes a checkpoint continues from what a restart
  // from it has (the last two states, the line, no stages)
  resume(out);
}

void Integrator::resume(const LoopState& saved) {
  pastStates_[1] = saved.predictorStart;
  pastStates_[0] = saved.predictorEnd;
  pastTimes_[1] = saved.predictorTime;
  pastTimes_[0] = saved.predictorTime + saved.predictorDt;
  pastCount_ = 2;  // a checkpoint before the first step holds no time: nothing continues it
  predictorDegree_.fill(1);
  // as a fresh integrator has them: a restart takes the same Newton path as the run it continues
  motionResolved_ = stageMissKept_ = oneFactorisationSufficed_ = false;
}

}  // namespace mpx
