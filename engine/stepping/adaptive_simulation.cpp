#include "engine/stepping/adaptive_simulation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

namespace mpx {

namespace {

// Step-size control of the usual kind (Hairer, Norsett & Wanner I, II.4): the next step is
// dt (safety / err)^(1/3) for a local error of order 3, limited per step.
constexpr double kSafety = 0.9;
constexpr double kLargestGrowth = 2.0;
constexpr double kLargestShrink = 0.2;
constexpr double kShrinkAfterNewtonFailure = 0.25;
// A step below this fraction of t_end ends the run as a failure.
constexpr double kSmallestStepFraction = 1e-12;

double stepFactor(double error) {
  if (!(error > 0.0)) return kLargestGrowth;
  return std::clamp(kSafety * std::cbrt(1.0 / error), kLargestShrink, kLargestGrowth);
}

// The dofs whose error is tested: positions, thermal and internal variables. Multipliers are
// left out, as IDA leaves out algebraic variables. So are velocities: each step's mean velocity
// is its position difference quotient, so their error shows in the positions one step later,
// while under constraints the end-point velocities of midpoint-type schemes carry a
// step-to-step oscillation of fixed size, which a third difference reads as an error that no
// step size reduces.
std::vector<int> testedDofs(const Layout& layout) {
  std::vector<int> dofs;
  for (int i = 0; i < layout.offset(Block::Multiplier); ++i)
    if (layout.blockOf(i) != Block::Velocity) dofs.push_back(i);
  return dofs;
}

// The local error of a step of a second-order one-step scheme, dt^3 |z'''| / 12 (the
// trapezoidal rule's exactly, the midpoint rule's for linear systems), with z''' = 6 z[t0..t3]
// from the last three accepted states of the current smooth stretch and the new one, in IDA's
// weighted RMS norm over the tested dofs.
class LocalError {
 public:
  LocalError(const Model& model, const StepControl& control)
      : rtol_(control.relativeTolerance),
        atolScale_(control.absoluteTolerance * model.dofScale()),
        tested_(testedDofs(model.layout())) {
    for (Eigen::VectorXd& state : states_) state.resize(model.layout().total());
  }

  // Start a new smooth stretch at (t, z): the loads have a kink here, or the run starts.
  void restart(double t, const Eigen::VectorXd& z) {
    count_ = 0;
    accept(t, z);
  }
  void accept(double t, const Eigen::VectorXd& z) {
    std::rotate(times_.begin(), times_.begin() + 1, times_.end());
    std::rotate(states_.begin(), states_.begin() + 1, states_.end());
    times_.back() = t;
    states_.back() = z;
    count_ = std::min(count_ + 1, kHistory);
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
  }
  // True when three states of this stretch are known, so that ofStep applies.
  bool hasHistory() const { return count_ == kHistory; }

  // The error norm of the step from the last accepted state to (t, z).
  double ofStep(double t, const Eigen::VectorXd& z) const {
    const auto& [t0, t1, t2] = times_;
    const Eigen::VectorXd &z0 = states_[0], &z1 = states_[1], &z2 = states_[2];
    const double dt = t - t2;
    double sum = 0.0;
    for (int i : tested_) {
      const double d01 = (z1[i] - z0[i]) / (t1 - t0), d12 = (z2[i] - z1[i]) / (t2 - t1), d23 = (z[i] - z2[i]) / dt;
      const double d0123 = ((d23 - d12) / (t - t1) - (d12 - d01) / (t2 - t0)) / (t - t0);
      sum += weighted(0.5 * dt * dt * dt * d0123, i);
    }
    return rms(sum);
  }
  // The error norm of two half steps that reached `halves` against one full step to `full`:
  // their difference is 3/4 of the full step's error, three times the halves'.
  double ofHalving(const Eigen::VectorXd& halves, const Eigen::VectorXd& full) const {
    double sum = 0.0;
    for (int i : tested_) sum += weighted((halves[i] - full[i]) / 3.0, i);
    return rms(sum);
  }

 private:
  static constexpr int kHistory = 3;
  // (error_i / (rtol |z_i| + atol scale_i))^2 at the start of the step
  double weighted(double error, int i) const {
    const double e = error / (rtol_ * std::abs(states_.back()[i]) + atolScale_[i]);
    return e * e;
  }
  double rms(double sum) const { return tested_.empty() ? 0.0 : std::sqrt(sum / tested_.size()); }

  double rtol_;
  Eigen::VectorXd atolScale_;
  std::vector<int> tested_;  // the dofs in the error test
  std::array<double, kHistory> times_{};
  std::array<Eigen::VectorXd, kHistory> states_;
  int count_ = 0;
};

// Where steps must land: load breakpoints, multiples of the output interval, t_end.
class Landings {
 public:
  Landings(const std::vector<double>& breakpoints, double outputInterval, double tEnd)
      : breakpoints_(breakpoints), interval_(outputInterval), tEnd_(tEnd) {}

  // The first landing time after t, and whether the loads have a kink there.
  std::pair<double, bool> after(double t) const {
    // landings within `slack` of each other are one (k * interval may fall ulps short of a
    // breakpoint or of t_end); the breakpoint or t_end is the one kept
    const double slack = 1e-12 * tEnd_;
    double next = tEnd_;
    if (interval_ > 0.0) next = std::min(next, (std::floor((t + slack) / interval_) + 1.0) * interval_);
    if (next > tEnd_ - slack) next = tEnd_;
    const auto kink = std::upper_bound(breakpoints_.begin(), breakpoints_.end(), t + slack);
    if (kink != breakpoints_.end() && *kink <= next + slack) return {*kink, true};
    return {next, false};
  }

 private:
  const std::vector<double>& breakpoints_;
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
  summary.linearSystem = integrator.linearSolver().describe();
  const Checkpointing& checkpoints = options.checkpoints;
  RunReporter reporter(model, summary, sink, progress, options.tEnd, checkpoints.resume);
  LocalError localError(model, control);
  const Landings landings(model.loadBreakpoints(), control.outputInterval, options.tEnd);
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
      proposed = dt * (std::isfinite(error) ? stepFactor(error) : kShrinkAfterNewtonFailure);
      if (proposed >= smallest) continue;
      summary.failed = true;
      summary.failedStep = accepted + 1;
      summary.failedTime = t;
      char what[sizeof newtonFailure + 100];
      std::snprintf(what, sizeof what, "adaptive step fell below %.3g (the last one tried, %.3g, %s)", smallest, dt,
                    std::isfinite(error) ? "failed the error test" : newtonFailure);
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
    const double allowed = takenError > 0.0 ? kSafety * std::cbrt(1.0 / takenError) : INFINITY;
    proposed = lands && taken < proposed ? std::min(proposed, taken * std::max(kLargestShrink, allowed))
                                         : taken * stepFactor(takenError);
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
  reporter.finish();
  return summary;
}

}  // namespace mpx
