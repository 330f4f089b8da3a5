#pragma once
// The time loop: advance a model with one integrator at a fixed step, report every step to a
// sink, and summarise the run (cost, conservation, failure).
#include "integrator.hpp"

#include <functional>
#include <optional>
#include <string>

namespace mpx {

struct RunOptions {
  Scheme scheme = Scheme::Eem;
  double dt = 0.0;
  double tEnd = 0.0;
  NewtonSettings newton;
};

// What one step reports; energies that crossed the boundary are accumulated since t = 0.
struct StepRecord {
  int step = 0;
  double time = 0.0;
  const Eigen::VectorXd* state = nullptr;
  const Measures* measures = nullptr;
  double dissipated = 0.0;
  double externalWork = 0.0;
  double boundaryHeat = 0.0;
  int newtonIterations = 0;
  int cutbacks = 0;
};

// SUNDIALS IDA's counters for a run (see engine/ida_simulation.hpp).
struct IdaStatistics {
  long steps = 0;
  long residualEvaluations = 0;
  long jacobianEvaluations = 0;
  long nonlinearIterations = 0;
  long errorTestFailures = 0;
};

struct RunSummary {
  int steps = 0;
  long newtonIterations = 0;
  int cutbacks = 0;
  double wallSeconds = 0.0;
  // max_n |E_n + D_n - W_n - Q_n - E_0| / |E_0|: energy drift net of dissipated energy D,
  // external work W and boundary heat Q (the plain energy drift for an isolated system)
  double maxEnergyBalanceError = 0.0;
  double minEntropyIncrement = 0.0;  // min_n (S_n - S_{n-1})
  std::optional<IdaStatistics> ida;  // set for IDA runs
  bool failed = false;
  int failedStep = 0;
  double failedTime = 0.0;
  std::string failure;
};

// Keeps a run summary's conservation figures (energy balance error, entropy increments) up to
// date as step records arrive; shared by the fixed-step and the IDA loops.
class ConservationMonitor {
 public:
  ConservationMonitor(const Measures& initial, RunSummary& summary);
  void observe(const StepRecord& record);

 private:
  double initialEnergy_, previousEntropy_;
  RunSummary& summary_;
};

using StepSink = std::function<void(const StepRecord&)>;
// Called with the fraction of the run done, at most about a hundred times.
using ProgressSink = std::function<void(double)>;

// Run from the model's initial state; step 0 reports the initial state. Stops at the first
// step the integrator cannot complete (after its cut-backs) and reports it in the summary.
RunSummary simulate(const Model& model, const RunOptions& options, const StepSink& sink,
                    const ProgressSink& progress = nullptr);

}  // namespace mpx
