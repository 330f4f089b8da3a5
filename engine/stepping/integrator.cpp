#include "engine/stepping/integrator.hpp"

#include "engine/core/collocation_rule.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace mpx {

namespace {
// eem4's stage miss scales to a step at most this much longer than the step it was seen on.
constexpr double kLargestMissScaling = 8.0;

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
      // step's miss, scaled to this step, is added (not after a much shorter step, a sliver before
      // a load breakpoint, whose miss is round-off that the scaling would blow up)
      stagePrediction_ = stages_;
      stagesPredicted_ = true;
      if (stageMissKept_ && motionResolved_ && dt <= kLargestMissScaling * stageMissDt_)
        stages_ += std::pow(dt / stageMissDt_, 3) * stageMiss_;
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
