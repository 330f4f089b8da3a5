#pragma once
// The time loop: advance a model with one integrator at a fixed step, report every step to a
// sink, and summarise the run (cost, conservation, failure). Adaptive steps:
// engine/stepping/adaptive_simulation.hpp.
#include "engine/stepping/integrator.hpp"
#include "engine/stepping/loop_state.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <optional>
#include <string>

namespace mpx {

struct RunOptions {
  Scheme scheme = Scheme::Eem;
  double dt = 0.0;  // the step (the first step of an adaptive run)
  double tEnd = 0.0;
  NewtonSettings newton;
  Checkpointing checkpoints;
  bool componentFlows = false;  // report the flows per component too (StepRecord::componentCrossed)
};

// What one step reports; energies that crossed the boundary are accumulated since t = 0.
struct StepRecord {
  int step = 0;
  double time = 0.0;
  double dt = 0.0;  // of the step that ended here (IDA: its last internal step)
  const Eigen::VectorXd* state = nullptr;
  const Measures* measures = nullptr;
  Flows crossed;
  int newtonIterations = 0;
  int cutbacks = 0;
  double initialEntropy = 0.0;  // S at t = 0, against which entropy production is counted
  // `crossed` per component in the model's order, then the prescribed motions' reactions;
  // set when the run keeps them (RunOptions::componentFlows)
  const std::vector<Flows>* componentCrossed = nullptr;
};

// The flows of a one-step run per component, summed since t = 0 over the accepted steps: each
// attempt gets its own slot from Integrator::advance, an accepted attempt's slot is added.
// Without `kept` it holds nothing and hands out null slots.
class ComponentFlows {
 public:
  ComponentFlows(const Model& model, bool kept, int slots);
  std::vector<Flows>* slot(int k) { return kept_ ? &slots_[k] : nullptr; }
  void accept(int k);
  const std::vector<Flows>* crossed() const { return kept_ ? &crossed_ : nullptr; }

 private:
  bool kept_;
  std::vector<std::vector<Flows>> slots_;
  std::vector<Flows> crossed_;
};

// SUNDIALS IDA's counters for a run (see engine/ida_simulation.hpp).
struct IdaStatistics {
  long steps = 0;
  long residualEvaluations = 0;
  long jacobianEvaluations = 0;
  long nonlinearIterations = 0;
  long errorTestFailures = 0;
  long convergenceFailures = 0;  // of the nonlinear (Newton) solver
};

// The energy balance E + D - W - Q - E_0 of a run: the largest |balance| so far relative to the
// largest of |E_0|, |E|, D, |W| and |Q| so far, so that a scene started from rest (E_0 = 0)
// is judged against the energy its loads put in, not against its first tiny step. At the end
// of a run both maxima are the whole run's.
class EnergyBalance {
 public:
  explicit EnergyBalance(double initialEnergy) : initial_(initialEnergy), scale_(std::abs(initialEnergy)) {}
  // A balance kept so far (restart).
  EnergyBalance(double initialEnergy, double scale, double largestError)
      : initial_(initialEnergy), scale_(scale), largestError_(largestError) {}
  double relativeError(double energy, double dissipated, double externalWork, double boundaryHeat) {
    scale_ = std::max({scale_, std::abs(energy), std::abs(dissipated), std::abs(externalWork), std::abs(boundaryHeat)});
    largestError_ = std::max(largestError_, std::abs(energy + dissipated - externalWork - boundaryHeat - initial_));
    return scale_ > 0.0 ? largestError_ / scale_ : largestError_;
  }
  double largestError() const { return largestError_; }
  double initial() const { return initial_; }
  double scale() const { return scale_; }

 private:
  double initial_, scale_, largestError_ = 0.0;
};

// A run whose largest relative energy balance error exceeds this has blown up: the one
// threshold of bench (against EnergyBalance's scale) and of the tests (against |E_0|, for runs
// that start with energy).
inline constexpr double kBlowUpEnergyError = 0.1;

struct RunSummary {
  int steps = 0;
  long newtonIterations = 0;
  long factorizations = 0;  // of the step tangent (one-step schemes)
  int cutbacks = 0;
  int rejectedSteps = 0;  // by the error test of adaptive steps
  double wallSeconds = 0.0;
  // max_n |E_n + D_n - W_n - Q_n - E_0| relative to the largest energy of the run (EnergyBalance):
  // energy drift net of dissipated energy D, external work W and boundary heat Q (the plain
  // energy drift for an isolated system); and the same maximum in joules
  double maxEnergyBalanceError = 0.0;
  double maxAbsoluteEnergyBalanceError = 0.0;
  double minEntropyProduction = 0.0;  // min_n of S_n - S_{n-1} minus the entropy brought in
  std::optional<IdaStatistics> ida;   // set for IDA runs
  std::string linearSystem;           // what each Newton iteration factorises (one-step schemes)
  bool failed = false;
  int failedStep = 0;
  double failedTime = 0.0;
  std::string failure;
  bool interrupted = false;  // stopped by requestStop() after `steps` steps, at interruptedTime
  double interruptedTime = 0.0;
};

// A stop asked for from outside the run (the CLI's SIGINT and SIGTERM handlers): every time loop
// ends after its next reported step (IDA: at once, ending at its last output time), with the summary marked
// interrupted. Safe to call from a signal handler; a request holds for the rest of the process.
void requestStop() noexcept;
bool stopRequested() noexcept;

using StepSink = std::function<void(const StepRecord&)>;
// Called with the fraction of the run done, at most about a hundred times.
using ProgressSink = std::function<void(double)>;

// What the time loops share: the current state, its measures and the record handed to the
// sink; the summary's conservation figures (energy balance error, entropy increments) and
// wall time; the progress bar. Constructing it reports the initial state as step 0, or the
// step a restart resumes from, with the summary's figures as they were there.
class RunReporter {
 public:
  RunReporter(const Model& model, RunSummary& summary, StepSink sink, ProgressSink progress, double tEnd,
              const LoopState* resume = nullptr);

  // The state the next report() describes; loops advance it in place.
  Eigen::VectorXd& state() { return state_; }
  const StepRecord& last() const { return record_; }
  // Report state() as `step` at `time`, reached by a step of `dt`; `crossed` holds the
  // energies crossed since t = 0. False when the run must stop: the state, its measures or the
  // flows are not finite (a failure in the summary, nothing handed to the sink; state() then
  // holds the rejected state), or a stop was requested before tEnd (the step reported, the
  // summary marked interrupted).
  bool report(int step, double time, double dt, const Flows& crossed, int newtonIterations, int cutbacks,
              const std::vector<Flows>* componentCrossed = nullptr);
  // Record the wall time since construction in the summary.
  void finish();
  // The last report and the summary's running figures, into a checkpoint.
  void save(LoopState& out) const;

 private:
  const Model& model_;
  RunSummary& summary_;
  StepSink sink_;
  ProgressSink progress_;
  double tEnd_, nextProgress_;
  Eigen::VectorXd state_;
  Measures measures_;
  StepRecord record_;
  EnergyBalance balance_{0.0};
  double previousEntropy_ = 0.0;  // S minus the entropy brought in, at the last report
  std::chrono::steady_clock::time_point start_;
};

// Run from the model's initial state; step 0 reports the initial state. Stops at the first
// step the integrator cannot complete (after its cut-backs) and reports it in the summary.
// With options.checkpoints: a checkpoint every `every` steps and at a stop request, or a
// run resumed from one.
RunSummary simulate(const Model& model, const RunOptions& options, const StepSink& sink,
                    const ProgressSink& progress = nullptr);

}  // namespace mpx
