#include "engine/stepping/simulation.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

namespace mpx {

RunReporter::RunReporter(const Model& model, RunSummary& summary, StepSink sink, ProgressSink progress, double tEnd,
                         const LoopState* resume)
    : model_(model),
      summary_(summary),
      sink_(std::move(sink)),
      progress_(std::move(progress)),
      tEnd_(tEnd),
      nextProgress_(0.01 * tEnd),
      state_(resume ? resume->state : model.initialState()),
      start_(std::chrono::steady_clock::now()) {
  model_.measure(state_, measures_);
  balance_ = EnergyBalance(measures_.energy);
  previousEntropy_ = measures_.entropy;
  record_.state = &state_;
  record_.measures = &measures_;
  record_.initialEntropy = measures_.entropy;
  if (resume) {
    record_.initialEntropy = resume->initialEntropy;
    balance_ = EnergyBalance(resume->initialEnergy, resume->energyScale, resume->largestEnergyError);
    previousEntropy_ = resume->previousEntropy;
    record_.step = resume->step;
    record_.time = resume->time;
    record_.dt = resume->dt;
    record_.crossed = resume->crossed;
    record_.newtonIterations = resume->newtonIterations;
    record_.cutbacks = resume->cutbacks;
    summary_.steps = resume->step;
    summary_.newtonIterations = resume->totalNewtonIterations;
    summary_.factorizations = resume->factorizations;
    summary_.cutbacks = resume->totalCutbacks;
    summary_.rejectedSteps = resume->rejectedSteps;
    summary_.maxAbsoluteEnergyBalanceError = balance_.largestError();
    summary_.maxEnergyBalanceError =
        balance_.scale() > 0.0 ? balance_.largestError() / balance_.scale() : balance_.largestError();
    summary_.minEntropyProduction = resume->minEntropyProduction;
    nextProgress_ = resume->time + 0.01 * tEnd;
  }
  sink_(record_);
}

void RunReporter::save(LoopState& out) const {
  out.step = record_.step;
  out.time = record_.time;
  out.dt = record_.dt;
  out.state = state_;
  out.crossed = record_.crossed;
  out.newtonIterations = record_.newtonIterations;
  out.cutbacks = record_.cutbacks;
  out.totalNewtonIterations = summary_.newtonIterations;
  out.factorizations = summary_.factorizations;
  out.totalCutbacks = summary_.cutbacks;
  out.rejectedSteps = summary_.rejectedSteps;
  out.initialEnergy = balance_.initial();
  out.energyScale = balance_.scale();
  out.largestEnergyError = balance_.largestError();
  out.initialEntropy = record_.initialEntropy;
  out.previousEntropy = previousEntropy_;
  out.minEntropyProduction = summary_.minEntropyProduction;
}

namespace {

// lock-free, so a signal handler may set it
std::atomic<bool> stopRequest{false};
static_assert(std::atomic<bool>::is_always_lock_free);

bool finite(const Flows& f) {
  return std::isfinite(f.dissipated) && std::isfinite(f.externalWork) && std::isfinite(f.boundaryHeat) &&
         std::isfinite(f.boundaryEntropy);
}

// Which dof of `z`, or which component's measures, or which flow is not finite (a state the
// residual accepted can still give a NaN energy, e.g. a logarithm of a quantity gone negative).
std::string describeNonFinite(const Model& model, const Eigen::VectorXd& z, const Measures& measures,
                              const Flows& crossed) {
  for (Eigen::Index dof = 0; dof < z.size(); ++dof) {
    if (std::isfinite(z[dof])) continue;
    std::string owner;
    for (const auto& component : model.components())
      if (std::find(component->dofs().begin(), component->dofs().end(), dof) != component->dofs().end()) {
        owner = " of " + component->name();
        break;
      }
    return "the state at dof " + std::to_string(dof) + " (" +
           std::string(blockName(model.layout().blockOf(static_cast<int>(dof)))) + owner + ") is not finite";
  }
  if (!finite(measures))
    for (const auto& component : model.components()) {
      Measures own;
      own.nodeTemperature.assign(measures.nodeTemperature.size(), 0.0);
      component->measure(z.data(), own);
      if (!finite(own))
        return "the energy, entropy, momentum or a temperature measured by " + component->name() +
               " is not finite (E = " + std::to_string(own.energy) + ", S = " + std::to_string(own.entropy) + ")";
    }
  if (!finite(crossed)) return "the dissipated energy, external work or boundary heat is not finite";
  return "the measures of the state are not finite";
}

}  // namespace

void requestStop() noexcept { stopRequest = true; }
bool stopRequested() noexcept { return stopRequest; }

bool RunReporter::report(int step, double time, double dt, const Flows& crossed, int newtonIterations, int cutbacks,
                         const std::vector<Flows>* componentCrossed) {
  model_.measure(state_, measures_);
  // a non-finite state or output ends the run here, before it reaches the history
  if (!state_.allFinite() || !finite(measures_) || !finite(crossed)) {
    summary_.failed = true;
    summary_.failedStep = step;
    summary_.failedTime = record_.time;  // the last good record's: where the failing step (IDA: interval) began
    summary_.failure = describeNonFinite(model_, state_, measures_, crossed);
    return false;
  }
  record_.step = step;
  record_.time = time;
  record_.dt = dt;
  record_.crossed = crossed;
  record_.newtonIterations = newtonIterations;
  record_.cutbacks = cutbacks;
  record_.componentCrossed = componentCrossed;
  sink_(record_);

  // conservation figures: the energy balance against t = 0, the smallest entropy production of a step
  summary_.maxEnergyBalanceError =
      balance_.relativeError(measures_.energy, crossed.dissipated, crossed.externalWork, crossed.boundaryHeat);
  summary_.maxAbsoluteEnergyBalanceError = balance_.largestError();
  const double produced = measures_.entropy - crossed.boundaryEntropy - previousEntropy_;
  summary_.minEntropyProduction = step == 1 ? produced : std::min(summary_.minEntropyProduction, produced);
  previousEntropy_ = measures_.entropy - crossed.boundaryEntropy;
  summary_.steps = step;
  // at most about a hundred progress reports
  if (progress_ && time >= nextProgress_) {
    progress_(std::min(1.0, time / tEnd_));
    nextProgress_ = time + 0.01 * tEnd_;
  }
  // a run that reached t_end is complete, even if a stop came during its last step doubling
  if (time >= tEnd_) summary_.interrupted = false;
  if (!stopRequested() || time >= tEnd_) return true;
  summary_.interrupted = true;
  summary_.interruptedTime = time;
  return false;
}

void RunReporter::finish() {
  summary_.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

ComponentFlows::ComponentFlows(const Model& model, bool kept, int slots) : kept_(kept) {
  if (!kept) return;
  const std::size_t entries = model.components().size() + 1;  // and the prescribed motions
  slots_.assign(slots, std::vector<Flows>(entries));
  crossed_.assign(entries, Flows{});
}

void ComponentFlows::accept(int k) {
  if (!kept_) return;
  for (std::size_t c = 0; c < crossed_.size(); ++c) crossed_[c] += slots_[k][c];
}

namespace {
// A load breakpoint closer than this fraction of dt to a step's end is taken to be there.
constexpr double kKinkSlack = 1e-6;
}  // namespace

RunSummary simulate(const Model& model, const RunOptions& options, const StepSink& sink, const ProgressSink& progress) {
  RunSummary summary;
  Integrator integrator(model, options.scheme, options.newton);
  const Checkpointing& checkpoints = options.checkpoints;
  RunReporter reporter(model, summary, sink, progress, options.tEnd, checkpoints.resume);
  if (checkpoints.resume) integrator.resume(*checkpoints.resume);
  Eigen::VectorXd next(reporter.state().size());
  Flows crossed = reporter.last().crossed;
  ComponentFlows byComponent(model, options.componentFlows, 1);
  CheckpointSchedule schedule(checkpoints, reporter.last().step);
  const double slack = kKinkSlack * options.dt;
  // One step from the last record's time to `end` over dt; false once the run stops there.
  int n = reporter.last().step;
  auto stepTo = [&](double end, double dt) {
    const double t = reporter.last().time;
    const StepOutcome outcome = integrator.advance(reporter.state(), t, dt, next, byComponent.slot(0));
    summary.newtonIterations += outcome.iterations;
    summary.cutbacks += outcome.cutbacks;
    summary.factorizations += outcome.factorizations;
    if (!outcome.converged) {
      summary.failed = true;
      summary.failedStep = n + 1;
      summary.failedTime = t;
      summary.failure = outcome.failure;
      return false;
    }
    reporter.state().swap(next);
    crossed += outcome.energy;
    byComponent.accept(0);
    return reporter.report(++n, end, dt, crossed, outcome.iterations, outcome.cutbacks, byComponent.crossed());
  };
  // Steps of dt, the last one over what remains to tEnd (a remainder below 1e-9 dt is dropped);
  // the step count, not the time summed step by step, says which step is the last.
  const auto steps = static_cast<long long>(std::ceil(options.tEnd / options.dt - 1e-9));
  // A step with load breakpoints inside ends on each of them before it goes on to its end: a
  // step's polynomial cannot follow a kink (eem4 across one is second order), and the steps
  // still end on the multiples of dt.
  while (reporter.last().time < options.tEnd) {
    const double t = reporter.last().time;
    const bool last = std::llround(t / options.dt) + 1 >= steps;
    const double end = last ? options.tEnd : t + options.dt;
    // first to each load breakpoint inside the step; a stop request waits for the step's end,
    // where a checkpoint can take the run up again
    bool split = false;
    while (!summary.failed) {
      const double kink = model.nextLoadBreakpoint(reporter.last().time + slack);
      if (!(kink < end - slack)) break;
      stepTo(kink, kink - reporter.last().time);
      split = true;
    }
    if (summary.failed) break;
    const double dt = split || last ? end - reporter.last().time : options.dt;
    const bool goOn = stepTo(end, dt);
    if (summary.failed) break;
    if (schedule.due(n, summary.interrupted)) {
      LoopState saved;
      reporter.save(saved);
      integrator.checkpoint(saved);
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
