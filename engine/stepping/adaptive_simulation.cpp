#include "engine/stepping/adaptive_simulation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

namespace mpx {

namespace {

// Step-size control of the usual kind (Hairer, Norsett & Wanner I, II.4): the next step is
// dt (safety / err)^(1/(p + 1)) for a scheme of order p, limited per step.
constexpr double kSafety = 0.9;
constexpr double kLargestGrowth = 2.0;
constexpr double kLargestShrink = 0.2;
constexpr double kShrinkAfterNewtonFailure = 0.25;
// A step below this fraction of t_end ends the run as a failure.
constexpr double kSmallestStepFraction = 1e-12;

// The dofs whose error is tested: positions, thermal and internal variables. Multipliers are
// left out, as IDA leaves out algebraic variables. So are velocities: each step's mean velocity
// is its position difference quotient, so their error shows in the positions one step later,
// while under constraints the end-point velocities of midpoint-type schemes carry a
// step-to-step oscillation of fixed size, which a divided difference reads as an error that no
// step size reduces (and eem4's carry a constraint-normal part of size O(dt^2)).
std::vector<int> testedDofs(const Layout& layout) {
  std::vector<int> dofs;
  for (int i = 0; i < layout.offset(Block::Multiplier); ++i)
    if (layout.blockOf(i) != Block::Velocity) dofs.push_back(i);
  return dofs;
}

// The local error of a step of a one-step scheme of order p, C dt^(p+1) |z^(p+1)|, with
// z^(p+1) = (p+1)! z[t0..t(p+1)] from the last p + 1 accepted states of the current smooth
// stretch and the new one, in IDA's weighted RMS norm over the tested dofs. C is the error
// constant of the schemes on z' = lambda z: 1/12 for the second-order ones (the trapezoidal
// rule's exactly, the midpoint rule's for linear systems), 1/720 for two-stage Gauss (eem4).
class LocalError {
 public:
  LocalError(const Model& model, const StepControl& control, int order)
      : order_(order),
        history_(order + 1),
        constant_(order == 4 ? 1.0 / 720.0 : 1.0 / 12.0),
        rtol_(control.relativeTolerance),
        atolScale_(control.absoluteTolerance * model.dofScale()),
        tested_(testedDofs(model.layout())) {
    static_assert(LoopState::kMostErrorHistory >= 4 + 1, "the history holds order + 1 states of eem4");
    if (order != 2 && order != 4) throw std::logic_error("LocalError knows the error constants of orders 2 and 4");
    // slots beyond this order's history stay zero (a checkpoint writes every slot)
    for (Eigen::VectorXd& state : states_) state.setZero(model.layout().total());
  }

  // The step factor for an error norm: (safety / err)^(1/(p + 1)), unlimited.
  double allowedFactor(double error) const {
    return error > 0.0 ? kSafety * std::pow(error, -1.0 / (order_ + 1)) : INFINITY;
  }
  double stepFactor(double error) const { return std::clamp(allowedFactor(error), kLargestShrink, kLargestGrowth); }

  // Start a new smooth stretch at (t, z): the loads have a kink here, or the run starts.
  void restart(double t, const Eigen::VectorXd& z) {
    count_ = 0;
    accept(t, z);
  }
  void accept(double t, const Eigen::VectorXd& z) {
    std::rotate(times_.begin(), times_.begin() + 1, times_.begin() + history_);
    std::rotate(states_.begin(), states_.begin() + 1, states_.begin() + history_);
    times_[history_ - 1] = t;
    states_[history_ - 1] = z;
    count_ = std::min(count_ + 1, history_);
  }
  void save(LoopState& out) const {
    out.errorHistoryCount = count_;
    out.errorTimes = times_;
    out.errorStates = states_;
  }
  void resume(const LoopState& saved) {
    count_ = saved.errorHistoryCount;
    times_ = saved.errorTimes;
    states_ = saved.errorStates;
    for (Eigen::VectorXd& state : states_)
      if (state.size() != atolScale_.size()) state.setZero(atolScale_.size());
  }
  // True when p + 1 states of this stretch are known, so that ofStep applies.
  bool hasHistory() const { return count_ == history_; }

  // The error norm of the step from the last accepted state to (t, z): the divided
  // differences of each tested dof over the history and the new point, built in place.
  double ofStep(double t, const Eigen::VectorXd& z) const {
    std::array<double, LoopState::kMostErrorHistory + 1> time{}, difference{};
    std::copy_n(times_.begin(), history_, time.begin());
    time[history_] = t;
    const double dt = t - times_[history_ - 1];
    double factorial = 1.0;
    for (int k = 2; k <= order_ + 1; ++k) factorial *= k;
    const double scale = constant_ * factorial * std::pow(dt, order_ + 1);
    double sum = 0.0;
    for (int i : tested_) {
      for (int k = 0; k < history_; ++k) difference[k] = states_[k][i];
      difference[history_] = z[i];
      for (int level = 1; level <= history_; ++level)
        for (int k = history_; k >= level; --k)
          difference[k] = (difference[k] - difference[k - 1]) / (time[k] - time[k - level]);
      sum += weighted(scale * difference[history_], i);
    }
    return rms(sum);
  }
  // The error norm of two half steps that reached `halves` against one full step to `full`:
  // their difference is (1 - 2^-p) of the full step's error, 2^p - 1 times the halves'.
  double ofHalving(const Eigen::VectorXd& halves, const Eigen::VectorXd& full) const {
    const double times = std::ldexp(1.0, order_) - 1.0;
    double sum = 0.0;
    for (int i : tested_) sum += weighted((halves[i] - full[i]) / times, i);
    return rms(sum);
  }

 private:
  // (error_i / (rtol |z_i| + atol scale_i))^2 at the start of the step
  double weighted(double error, int i) const {
    const double e = error / (rtol_ * std::abs(states_[history_ - 1][i]) + atolScale_[i]);
    return e * e;
  }
  double rms(double sum) const { return tested_.empty() ? 0.0 : std::sqrt(sum / tested_.size()); }

  int order_, history_;
  double constant_;
  double rtol_;
  Eigen::VectorXd atolScale_;
  std::vector<int> tested_;  // the dofs in the error test
  std::array<double, LoopState::kMostErrorHistory> times_{};
  std::array<Eigen::VectorXd, LoopState::kMostErrorHistory> states_;
  int count_ = 0;
};

// Where steps must land: load breakpoints, multiples of the output interval, t_end.
class Landings {
 public:
  Landings(const Model& model, double outputInterval, double tEnd)
      : model_(model), interval_(outputInterval), tEnd_(tEnd) {}

  // The first landing time after t, and whether the loads have a kink there.
  std::pair<double, bool> after(double t) const {
    // landings within `slack` of each other are one (k * interval may fall ulps short of a
    // breakpoint or of t_end); the breakpoint or t_end is the one kept
    const double slack = 1e-12 * tEnd_;
    double next = tEnd_;
    if (interval_ > 0.0) next = std::min(next, (std::floor((t + slack) / interval_) + 1.0) * interval_);
    if (next > tEnd_ - slack) next = tEnd_;
    const double kink = model_.nextLoadBreakpoint(t + slack);
    if (kink <= next + slack) return {kink, true};
    return {next, false};
  }

 private:
  const Model& model_;
  double interval_, tEnd_;
};

}  // namespace

RunSummary simulateAdaptive(const Model& model, const RunOptions& options, const StepControl& control,
                            const StepSink& sink, const ProgressSink& progress) {
  RunSummary summary;
  // a step Newton cannot solve is rejected and retried shorter, which takes the place of the
  // fixed-step loop's cut-backs (whose sub-steps would also make full and half steps alike)
  NewtonSettings newton = options.newton;
  newton.maxCutbacks = 0;
  Integrator integrator(model, options.scheme, newton);
  const Checkpointing& checkpoints = options.checkpoints;
  RunReporter reporter(model, summary, sink, progress, options.tEnd, checkpoints.resume);
  LocalError localError(model, control, schemeOrder(options.scheme));
  const Landings landings(model, control.outputInterval, options.tEnd);
  const int n = model.layout().total();
  Eigen::VectorXd next(n), half(n), fullStep(n);
  Flows crossed = reporter.last().crossed;
  // slots of the attempts: the full step, the first half, the step taken
  enum Attempt { kFull, kFirstHalf, kTaken };
  ComponentFlows byComponent(model, options.componentFlows, 3);
  int accepted = reporter.last().step;
  char newtonFailure[sizeof StepOutcome::failure] = "";
  // one step of the scheme, counted in the summary
  auto attempt = [&](const Eigen::VectorXd& from, double t, double dt, Eigen::VectorXd& to, StepOutcome& outcome,
                     Attempt slot) {
    newtonFailure[0] = '\0';
    outcome = integrator.advance(from, t, dt, to, byComponent.slot(slot));
    summary.newtonIterations += outcome.iterations;
    summary.cutbacks += outcome.cutbacks;
    summary.factorizations += outcome.factorizations;
    if (!outcome.converged) std::snprintf(newtonFailure, sizeof newtonFailure, "%s", outcome.failure);
    return outcome.converged;
  };
  auto accept = [&](Eigen::VectorXd& state, double time, double dt, const StepOutcome& outcome, Attempt slot) {
    reporter.state().swap(state);
    crossed += outcome.energy;
    byComponent.accept(slot);
    return reporter.report(++accepted, time, dt, crossed, outcome.iterations, outcome.cutbacks, byComponent.crossed());
  };

  double proposed = options.dt;
  localError.restart(0.0, reporter.state());
  if (checkpoints.resume) {
    integrator.resume(*checkpoints.resume);
    localError.resume(*checkpoints.resume);
    proposed = checkpoints.resume->proposedStep;
  }
  CheckpointSchedule schedule(checkpoints, accepted);
  const double smallest = kSmallestStepFraction * options.tEnd;
  while (reporter.last().time < options.tEnd) {
    const double t = reporter.last().time;
    const auto [landing, kink] = landings.after(t);
    // land on the next landing time, in two even steps where one would leave a sliver
    double dt = proposed;
    if (t + dt >= landing - 1e-9 * dt) {
      dt = landing - t;
    } else if (t + 2.0 * dt > landing) {
      dt = 0.5 * (landing - t);
    }
    const bool lands = dt == landing - t;
    const double tNew = lands ? landing : t + dt;

    // one step judged against the history, or without one, step doubling that keeps the halves
    double error = INFINITY;
    StepOutcome fullOutcome, firstHalfOutcome, stepOutcome;
    const bool doubling = !localError.hasHistory();
    if (doubling) {
      if (attempt(reporter.state(), t, dt, fullStep, fullOutcome, kFull) &&
          attempt(reporter.state(), t, 0.5 * dt, half, firstHalfOutcome, kFirstHalf) &&
          attempt(half, t + 0.5 * dt, 0.5 * dt, next, stepOutcome, kTaken))
        error = localError.ofHalving(next, fullStep);
    } else if (attempt(reporter.state(), t, dt, next, stepOutcome, kTaken)) {
      error = localError.ofStep(tNew, next);
    }

    if (!(error <= 1.0)) {
      ++summary.rejectedSteps;
      proposed = dt * (std::isfinite(error) ? localError.stepFactor(error) : kShrinkAfterNewtonFailure);
      if (proposed >= smallest) continue;
      summary.failed = true;
      summary.failedStep = accepted + 1;
      summary.failedTime = t;
      char what[sizeof newtonFailure + 100];
      std::snprintf(what, sizeof what, "adaptive step fell below %.3g (the last one tried, %.3g, %s)", smallest, dt,
                    newtonFailure[0] != '\0' ? newtonFailure : "failed the error test");
      summary.failure = what;
      break;
    }
    // a stop request after the first half still takes the second, so that a checkpoint
    // falls where a step is complete
    if (doubling) {
      if (!accept(half, t + 0.5 * dt, 0.5 * dt, firstHalfOutcome, kFirstHalf) && summary.failed) break;
      localError.accept(t + 0.5 * dt, reporter.state());
    }
    const bool goOn = accept(next, tNew, doubling ? 0.5 * dt : dt, stepOutcome, kTaken);
    if (summary.failed) break;
    // the next step from the last one taken and its own error (a half step of a doubling has
    // half the pair's); a step shortened to land may be followed by one up to the size
    // proposed before, as far as its error allows
    const double taken = doubling ? 0.5 * dt : dt, takenError = doubling ? 0.5 * error : error;
    const double allowed = localError.allowedFactor(takenError);
    proposed = lands && taken < proposed ? std::min(proposed, taken * std::max(kLargestShrink, allowed))
                                         : taken * localError.stepFactor(takenError);
    if (kink && lands) {
      localError.restart(tNew, reporter.state());
    } else {
      localError.accept(tNew, reporter.state());
    }
    if (schedule.due(accepted, summary.interrupted)) {
      LoopState saved;
      reporter.save(saved);
      integrator.checkpoint(saved);
      localError.save(saved);
      saved.proposedStep = proposed;
      checkpoints.write(saved);
    }
    if (!goOn) break;
  }
  // what factorised the steps in the end (a symmetric factorisation may have handed over to the LU)
  summary.linearSystem = integrator.linearSolver().describe();
  reporter.finish();
  return summary;
}

}  // namespace mpx
