// metriplex run and metriplex compare.
#include "tools/commands.hpp"
#include "tools/output/checkpoint_file.hpp"
#include "tools/output/frames_csv.hpp"
#include "tools/output/history_csv.hpp"
#include "tools/output/solid_frames.hpp"

#include "engine/core/input_error.hpp"
#include "engine/stepping/method.hpp"
#include "models/scene/scene_loader.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

namespace mpx {

namespace {

// A run whose input has been fully validated: nothing is written before this exists.
struct PreparedRun {
  Method method;
  CompiledScene scene;
  MethodParameters parameters;
  std::filesystem::path out;
  double frameInterval = 0.0;  // bodies.csv, joints.csv and solid frames
  CheckpointIdentity identity;
  std::optional<LoopState> resume;  // --restart
};

struct RunResult {
  std::string variable;
  RunSummary summary;
  std::filesystem::path history;
};

void checkPositive(std::optional<double> value, const char* option) {
  if (value && !(*value > 0.0 && std::isfinite(*value)))
    throw InputError(fmt::format("option {} must be a positive number, got {}", option, *value));
}

Method methodOrThrow(const std::string& name) {
  const std::optional<Method> method = methodByName(name);
  if (!method) throw InputError(fmt::format("unknown integrator '{}' (choose {})", name, kMethodNames));
  return *method;
}

// Draws a progress bar on a terminal; silent when stderr is redirected.
ProgressSink progressBar(const std::string& label) {
  if (!isatty(fileno(stderr))) return nullptr;
  return [label](double fraction) {
    const int width = 40, done = static_cast<int>(fraction * width);
    fmt::print(stderr, "\r{} [{}{}] {:3.0f}%", label, std::string(done, '#'), std::string(width - done, ' '),
               100 * fraction);
    if (fraction >= 1.0) fmt::print(stderr, "\n");
  };
}

// --checkpoint-every and --restart: what checkpoints identify, and the state a restart
// continues from (read and checked here, before anything is written).
void prepareCheckpoints(const RunRequest& request, PreparedRun& run) {
  if (request.checkpointEvery < 0)
    throw InputError(
        fmt::format("option --checkpoint-every must be 0 (none) or more, got {}", request.checkpointEvery));
  if (run.method.isIda() && (request.checkpointEvery > 0 || !request.restart.empty()))
    throw InputError(
        "options --checkpoint-every and --restart: integrator 'ida' cannot be checkpointed (its multistep history "
        "cannot be saved and restored through SUNDIALS' interface); use a one-step integrator");
  const MethodParameters& p = run.parameters;
  const bool tolerances = p.adaptive;
  run.identity = {run.scene.name,
                  hashOfFile(request.scene),
                  run.method.name,
                  p.adaptive,
                  run.scene.model->layout().total(),
                  p.dt,
                  tolerances ? p.relativeTolerance : 0.0,
                  tolerances ? p.absoluteTolerance : 0.0,
                  tolerances ? p.outputInterval : 0.0};
  if (request.restart.empty()) return;
  run.resume = readCheckpoint(request.restart, run.identity);
  if (!(run.resume->time < p.tEnd))
    throw InputError(fmt::format("option --restart: the checkpoint is at t = {:.17g}, not before t_end = {:.17g}",
                                 run.resume->time, p.tEnd));
}

// The default output directory is out/<scene>-<outSuffix>, or out/<scene>-<integrator> when
// outSuffix is empty.
PreparedRun prepare(const RunRequest& request, const std::string& outSuffix) {
  checkPositive(request.dt, "--dt");
  checkPositive(request.tEnd, "--t-end");
  checkPositive(request.relativeTolerance, "--rtol");
  checkPositive(request.absoluteTolerance, "--atol");
  checkPositive(request.outputStep, "--dt-out");
  if (request.maxOrder < 1 || request.maxOrder > 5)
    throw InputError(fmt::format("option --max-order must be 1 to 5, got {}", request.maxOrder));
  std::optional<Method> method;
  if (!request.integrator.empty()) method = methodOrThrow(request.integrator);
  CompiledScene scene = loadScene(request.scene, method ? method->thermalVariable : std::nullopt);
  if (!method) method = methodOrThrow(scene.settings.integrator);
  checkMethodSupports(*method, *scene.model, request.scene);

  MethodParameters parameters;
  parameters.dt = request.dt.value_or(scene.settings.dt);
  parameters.tEnd = request.tEnd.value_or(scene.settings.tEnd);
  parameters.newton = scene.settings.newton;
  parameters.adaptive = request.adaptive || scene.settings.adaptive || method->adaptive;
  const double sceneAtol = scene.settings.absoluteTolerance;
  parameters.relativeTolerance = request.relativeTolerance.value_or(scene.settings.relativeTolerance);
  parameters.absoluteTolerance = request.absoluteTolerance.value_or(
      request.relativeTolerance || sceneAtol == 0.0 ? parameters.relativeTolerance : sceneAtol);
  parameters.outputInterval = request.frameInterval.value_or(0.0);
  parameters.maxOrder = request.maxOrder;
  parameters.sundialsKlu = request.sundialsKlu;
  if (method->isIda()) parameters.dt = request.outputStep.value_or(parameters.dt);
  checkStepCount(parameters.tEnd, parameters.dt,
                 method->isIda() ? "options --t-end and --dt-out" : "options --t-end and --dt");
  std::filesystem::path out =
      request.out.empty()
          ? std::filesystem::path("out") / (scene.name + "-" + (outSuffix.empty() ? method->name : outSuffix))
          : std::filesystem::path(request.out);
  checkPositive(request.frameInterval, "--output-interval");
  PreparedRun run{*method, std::move(scene), parameters, std::move(out), request.frameInterval.value_or(0.0), {}, {}};
  prepareCheckpoints(request, run);
  return run;
}

// Checkpoints of `metriplex run`, under the output directory.
constexpr const char* kCheckpointFile = "checkpoint.txt";

// Runs and writes the outputs; with `checkpoints`, a one-step run writes DIR/checkpoint.txt
// every `checkpointEvery` steps and at a stop request, and continues from run.resume if set.
RunResult execute(const PreparedRun& run, bool checkpoints = false, int checkpointEvery = 0) {
  std::error_code error;
  std::filesystem::create_directories(run.out, error);
  if (error)
    throw InputError(
        fmt::format("option --out: cannot create the directory {}: {}", run.out.string(), error.message()));
  HistoryCsv history(run.out, run.scene);
  FramesCsv frames(run.out, run.scene, run.frameInterval);
  SolidFrames solids(run.out, run.scene, run.frameInterval);
  RunResult result{
      run.scene.model->thermalVariable() == ThermalVariable::Entropy ? "entropy" : "temperature", {}, history.path()};
  MethodParameters parameters = run.parameters;
  if (!run.method.isIda() && checkpoints) {
    parameters.checkpoints.every = checkpointEvery;
    parameters.checkpoints.resume = run.resume ? &*run.resume : nullptr;
    // a checkpoint that cannot be written (a full disk) is a warning: the run and its outputs go on
    parameters.checkpoints.write = [&](const LoopState& state) {
      try {
        writeCheckpoint((run.out / kCheckpointFile).string(), run.identity, state);
      } catch (const std::runtime_error& error) {
        fmt::print(stderr, "metriplex: warning: no checkpoint after step {}: {}\n", state.step, error.what());
      }
    };
  }
  result.summary = runMethod(
      *run.scene.model, run.method, parameters,
      [&](const StepRecord& r) {
        history.write(r);
        frames.write(r);
        solids.write(r);
      },
      progressBar(run.scene.name + " " + run.method.name));
  history.finish(result.summary);
  frames.finish();
  solids.finish();
  return result;
}

double perStep(long count, int steps) { return steps ? static_cast<double>(count) / steps : 0.0; }

void printSummary(const RunResult& r, const RunRequest& request, const PreparedRun& run) {
  const RunSummary& s = r.summary;
  fmt::print("metriplex run {} --integrator {}{} (thermal variable: {})\n", request.scene, run.method.name,
             run.parameters.adaptive && !run.method.isIda() ? " --adaptive" : "", r.variable);
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
  const PreparedRun run = prepare(request, "");
  const RunResult result = execute(run, true, request.checkpointEvery);
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
    runs.push_back(prepare(request, "compare"));
  }
  const std::filesystem::path root = base.out.empty() ? runs.front().out : std::filesystem::path(base.out);
  fmt::print("{:<16} {:>8} {:>12} {:>10} {:>16} {:>16}  {}\n", "integrator", "steps", "newton/step", "wall [s]",
             "max energy drift", "min production", "status");
  // a blow-up is a finding here, not an error
  for (PreparedRun& run : runs) {
    run.out = root / run.method.name;
    const RunResult r = execute(run);
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
