#include "simulation.hpp"

#include <chrono>
#include <cmath>

namespace mpx {

ConservationMonitor::ConservationMonitor(const Measures& initial, RunSummary& summary)
    : initialEnergy_(initial.energy), previousEntropy_(initial.entropy), summary_(summary) {}

void ConservationMonitor::observe(const StepRecord& r) {
  const Measures& m = *r.measures;
  const double balance = m.energy + r.dissipated - r.externalWork - r.boundaryHeat - initialEnergy_;
  summary_.maxEnergyBalanceError = std::max(summary_.maxEnergyBalanceError, std::abs(balance) / std::abs(initialEnergy_));
  const double entropyIncrement = m.entropy - previousEntropy_;
  summary_.minEntropyIncrement =
      r.step == 1 ? entropyIncrement : std::min(summary_.minEntropyIncrement, entropyIncrement);
  previousEntropy_ = m.entropy;
  summary_.steps = r.step;
}

RunSummary simulate(const Model& model, const RunOptions& options, const StepSink& sink,
                    const ProgressSink& progress) {
  RunSummary summary;
  Integrator integrator(model, options.scheme, options.newton);
  Eigen::VectorXd state = model.initialState(), next(state.size());
  Measures measures;
  model.measure(state, measures);
  ConservationMonitor monitor(measures, summary);

  StepRecord record;
  record.state = &state;
  record.measures = &measures;
  sink(record);

  // the last step is shortened to land on tEnd; a remainder below 1e-9 dt is dropped
  const auto steps = static_cast<int>(std::ceil(options.tEnd / options.dt - 1e-9));
  const int progressEvery = std::max(1, steps / 100);
  const auto start = std::chrono::steady_clock::now();
  for (int n = 1; n <= steps; ++n) {
    const double t = record.time;
    const double dt = std::min(options.dt, options.tEnd - t);
    const StepOutcome outcome = integrator.advance(state, t, dt, next);
    summary.newtonIterations += outcome.iterations;
    summary.cutbacks += outcome.cutbacks;
    if (!outcome.converged) {
      summary.failed = true;
      summary.failedStep = n;
      summary.failedTime = t;
      summary.failure = outcome.failure;
      break;
    }
    state.swap(next);
    model.measure(state, measures);
    record.step = n;
    record.time = n == steps ? options.tEnd : t + dt;
    record.dissipated += outcome.energy.dissipated;
    record.externalWork += outcome.energy.externalWork;
    record.boundaryHeat += outcome.energy.boundaryHeat;
    record.newtonIterations = outcome.iterations;
    record.cutbacks = outcome.cutbacks;
    sink(record);
    monitor.observe(record);
    if (progress && n % progressEvery == 0) progress(static_cast<double>(n) / steps);
  }
  summary.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace mpx
