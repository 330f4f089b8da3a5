// metriplex run and metriplex compare.
#include "tools/commands.hpp"
#include "tools/session/run_session.hpp"

#include "engine/core/input_error.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <chrono>

namespace mpx {

namespace {

// Draws a progress bar with the time left (elapsed wall time extrapolated over the fraction
// to go) on a terminal; silent when stderr is redirected.
ProgressSink progressBar(const std::string& label) {
  if (!isatty(fileno(stderr))) return nullptr;
  const auto start = std::chrono::steady_clock::now();
  return [label, start](double fraction) {
    const int width = 40, done = static_cast<int>(fraction * width);
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const std::string left = fraction > 0.0 && fraction < 1.0
                                 ? fmt::format("  ETA {:.0f} s  ", elapsed * (1.0 - fraction) / fraction)
                                 : fmt::format("  {:.1f} s      ", elapsed);
    fmt::print(stderr, "\r{} [{}{}] {:3.0f}%{}", label, std::string(done, '#'), std::string(width - done, ' '),
               100 * fraction, left);
    if (fraction >= 1.0) fmt::print(stderr, "\n");
  };
}

RunOutputs runOutputs(const PreparedRun& run, bool checkpoints, int checkpointEvery) {
  RunOutputs outputs;
  outputs.checkpoints = checkpoints;
  outputs.checkpointEvery = checkpointEvery;
  outputs.progress = progressBar(run.scene.name + " " + run.method.name);
  return outputs;
}

double perStep(long count, int steps) { return steps ? static_cast<double>(count) / steps : 0.0; }

void printSummary(const RunResult& r, const RunRequest& request, const PreparedRun& run) {
  const RunSummary& s = r.summary;
  fmt::print("metriplex run {} --integrator {}{} (thermal variable: {})\n", request.scene, run.method.name,
             run.parameters.adaptive && !run.method.isIda() ? " --adaptive" : "", run.thermalVariable());
  fmt::print("  steps                    {}{}\n", s.steps, s.ida ? " (output times)" : "");
  fmt::print("  newton iterations        {} ({:.2f} per step)\n", s.newtonIterations,
             perStep(s.newtonIterations, s.steps));
  if (s.ida) {
    fmt::print(
        "  IDA                      {} steps, {} residual evaluations, {} Jacobian evaluations, "
        "{} nonlinear iterations, {} error-test failures, {} convergence failures\n",
        s.ida->steps, s.ida->residualEvaluations, s.ida->jacobianEvaluations, s.ida->nonlinearIterations,
        s.ida->errorTestFailures, s.ida->convergenceFailures);
  } else {
    if (run.parameters.adaptive) fmt::print("  rejected steps           {}\n", s.rejectedSteps);
    fmt::print("  cut-backs                {}\n", s.cutbacks);
    fmt::print("  factorisations           {} ({:.2f} per step)\n", s.factorizations,
               perStep(s.factorizations, s.steps));
  }
  fmt::print("  linear system            {}\n", s.linearSystem);
  if (!run.scene.redundantConditions.empty())
    fmt::print("  redundant conditions     {} (multipliers held at zero)\n",
               describeRedundancy(run.scene.redundantConditions));
  fmt::print("  wall time                {:.3f} s\n", s.wallSeconds);
  fmt::print(
      "  max rel. energy drift    {:.3e}  (max |E + dissipated - external work - boundary heat - E0| / largest energy "
      "of the run; {:.3e} J)\n",
      s.maxEnergyBalanceError, s.maxAbsoluteEnergyBalanceError);
  fmt::print("  min entropy production   {:.3e}  (per step: S change minus entropy brought in)\n",
             s.minEntropyProduction);
  fmt::print("  history                  {}\n", r.history.string());
}

}  // namespace

int runCommand(const RunRequest& request) {
  const PreparedRun run = prepareRun(request);
  const RunResult result = executeRun(run, runOutputs(run, true, request.checkpointEvery));
  printSummary(result, request, run);
  if (result.summary.interrupted) {
    fmt::print(stderr, "metriplex: interrupted after step {} (t = {:.9g}); history kept in {}{}\n",
               result.summary.steps, result.summary.interruptedTime, result.history.string(),
               run.method.isIda() ? "" : "; continue with --restart " + (run.out / kCheckpointFile).string());
    return kExitInterrupted;
  }
  if (!result.summary.failed) return 0;
  fmt::print(stderr,
             "metriplex: solver failure at step {} (t = {:.9g}): {}; history kept up to the last good step in {}\n",
             result.summary.failedStep, result.summary.failedTime, result.summary.failure, result.history.string());
  return kExitSolverFailure;
}

int compareCommand(const RunRequest& base, const std::vector<std::string>& integrators) {
  // validate every run before the first one writes anything
  if (integrators.empty()) throw InputError("option --integrators: no integrator given");
  std::vector<PreparedRun> runs;
  for (const std::string& name : integrators) {
    RunRequest request = base;
    request.integrator = name;
    request.out.clear();
    runs.push_back(prepareRun(request, "compare"));
  }
  const std::filesystem::path root = base.out.empty() ? runs.front().out : std::filesystem::path(base.out);
  fmt::print("{:<16} {:>8} {:>12} {:>10} {:>16} {:>16}  {}\n", "integrator", "steps", "newton/step", "wall [s]",
             "max energy drift", "min production", "status");
  // a blow-up is a finding here, not an error
  for (PreparedRun& run : runs) {
    run.out = root / run.method.name;
    const RunResult r = executeRun(run, runOutputs(run, false, 0));
    const RunSummary& s = r.summary;
    const std::string status =
        s.interrupted ? fmt::format("interrupted after step {} (t = {:.6g})", s.steps, s.interruptedTime)
        : s.failed    ? fmt::format("failed at step {} (t = {:.6g}): {}", s.failedStep, s.failedTime, s.failure)
                      : "ok";
    fmt::print("{:<16} {:>8} {:>12.2f} {:>10.3f} {:>16.3e} {:>16.3e}  {}\n", run.method.name, s.steps,
               perStep(s.newtonIterations, s.steps), s.wallSeconds, s.maxEnergyBalanceError, s.minEntropyProduction,
               status);
    // an interruption stops the comparison: the integrators after it are not started
    if (s.interrupted) return kExitInterrupted;
  }
  fmt::print("histories in {}/<integrator>/history.csv\n", root.string());
  return 0;
}

}  // namespace mpx
