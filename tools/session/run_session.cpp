#include "tools/session/run_session.hpp"

#include "tools/output/atomic_file.hpp"
#include "tools/output/budget_csv.hpp"
#include "tools/output/frames_csv.hpp"
#include "tools/output/history_csv.hpp"
#include "tools/output/json_object.hpp"
#include "tools/output/solid_frames.hpp"

#include "engine/core/input_error.hpp"
#include "models/scene/urdf_scene.hpp"

#include <fmt/format.h>

#include <cmath>

namespace mpx {

namespace {

void checkPositive(std::optional<double> value, const char* option) {
  if (value && !(*value > 0.0 && std::isfinite(*value)))
    throw InputError(fmt::format("option {} must be a positive number, got {}", option, *value));
}

Method methodOrThrow(const std::string& name) {
  const std::optional<Method> method = methodByName(name);
  if (!method) throw InputError(fmt::format("unknown integrator '{}' (choose {})", name, kMethodNames));
  return *method;
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
  // a scene built in code has no file whose hash would tie a checkpoint to it
  if (request.spec && !request.restart.empty())
    throw InputError("option --restart: a scene built in code cannot be restarted; restart from its scene file");
  const MethodParameters& p = run.parameters;
  const bool tolerances = p.adaptive;
  run.identity = {run.scene.name,
                  request.spec ? std::string() : hashOfFile(request.scene),
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

// The scene file, a .urdf with its joint stops if asked for.
CompiledScene loadRequestedScene(const RunRequest& request, std::optional<ThermalVariable> variable) {
  if (!request.urdfLimits) return loadScene(request.scene, variable);
  if (std::filesystem::path(request.scene).extension() != ".urdf")
    throw InputError("option --urdf-limits: only for a .urdf scene; in an XML scene write <urdf ... limits=\"true\">");
  UrdfImportOptions options;
  options.limits = true;
  return compileScene(readUrdfScene(request.scene, options), variable);
}

std::string statusOf(const RunSummary& s) { return s.interrupted ? "interrupted" : s.failed ? "failed" : "ok"; }

}  // namespace

std::string PreparedRun::thermalVariable() const {
  return scene.model->thermalVariable() == ThermalVariable::Entropy ? "entropy" : "temperature";
}

PreparedRun prepareRun(const RunRequest& request, const std::string& outSuffix) {
  checkPositive(request.dt, "--dt");
  checkPositive(request.tEnd, "--t-end");
  checkPositive(request.relativeTolerance, "--rtol");
  if (request.relativeTolerance && *request.relativeTolerance < kSmallestRelativeTolerance)
    throw InputError(fmt::format("option --rtol must be at least {:g} (below, round-off exceeds it), got {}",
                                 kSmallestRelativeTolerance, *request.relativeTolerance));
  checkPositive(request.absoluteTolerance, "--atol");
  checkPositive(request.outputStep, "--dt-out");
  if (request.maxOrder && (*request.maxOrder < 1 || *request.maxOrder > 5))
    throw InputError(fmt::format("option --max-order must be 1 to 5, got {}", *request.maxOrder));
  std::optional<Method> method;
  if (!request.integrator.empty()) method = methodOrThrow(request.integrator);
  const std::optional<ThermalVariable> variable = method ? method->thermalVariable : std::nullopt;
  CompiledScene scene = request.spec ? compileScene(*request.spec, variable) : loadRequestedScene(request, variable);
  if (!method) method = methodOrThrow(scene.settings.integrator);
  checkMethodSupports(*method, *scene.model, request.scene);
  // IDA's options with another integrator would be silently ignored
  if (!method->isIda())
    for (const auto& [given, option] : {std::pair<bool, const char*>{request.maxOrder.has_value(), "--max-order"},
                                        {request.outputStep.has_value(), "--dt-out"},
                                        {request.sundialsKlu, "--sundials-klu"}})
      if (given) throw InputError(fmt::format("option {}: only for ida, not '{}'", option, method->name));
  if (method->maxOrder > 0 && request.maxOrder && *request.maxOrder != method->maxOrder)
    throw InputError(fmt::format("option --max-order {}: integrator '{}' sets the order to {} already",
                                 *request.maxOrder, method->name, method->maxOrder));

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
  parameters.maxOrder = request.maxOrder.value_or(parameters.maxOrder);
  parameters.sundialsKlu = request.sundialsKlu;
  if (method->isIda()) parameters.dt = request.outputStep.value_or(parameters.dt);
  checkStepCount(parameters.tEnd, parameters.dt,
                 method->isIda() ? "options --t-end and --dt-out" : "options --t-end and --dt");
  std::filesystem::path out =
      request.out.empty()
          ? std::filesystem::path("out") / (scene.name + "-" + (outSuffix.empty() ? method->name : outSuffix))
          : std::filesystem::path(request.out);
  checkPositive(request.frameInterval, "--output-interval");
  // adaptive steps land on every output time
  if (parameters.adaptive && request.frameInterval)
    checkStepCount(parameters.tEnd, *request.frameInterval, "options --t-end and --output-interval");
  // IDA integrates the summed flows as quadratures; a restart has no flows per element to resume
  if (request.budget && method->isIda())
    throw InputError("option --budget: integrator 'ida' integrates only the total flows; use a one-step integrator");
  if (request.budget && !request.restart.empty())
    throw InputError("options --budget and --restart: a checkpoint holds no flows per element; run from t = 0");
  parameters.componentFlows = request.budget;
  PreparedRun run{*method, std::move(scene), parameters, std::move(out), request.frameInterval.value_or(0.0), {}, {}};
  prepareCheckpoints(request, run);
  return run;
}

RunResult executeRun(const PreparedRun& run, const RunOutputs& outputs) {
  if (outputs.files) {
    std::error_code error;
    std::filesystem::create_directories(run.out, error);
    if (error)
      throw InputError(
          fmt::format("option --out: cannot create the directory {}: {}", run.out.string(), error.message()));
    // the files renamed into place at the end: a directory in their way would fail after the run
    for (const char* name : {"history.csv", "summary.json", "checkpoint.txt"})
      if (std::filesystem::exists(run.out / name) && !std::filesystem::is_regular_file(run.out / name))
        throw InputError(fmt::format("option --out: {} exists and is not a file", (run.out / name).string()));
  }
  std::optional<HistoryCsv> history;
  std::optional<FramesCsv> frames;
  std::optional<SolidFrames> solids;
  std::optional<BudgetCsv> budget;
  if (outputs.files) {
    history.emplace(run.out, run.scene);
    frames.emplace(run.out, run.scene, run.frameInterval);
    solids.emplace(run.out, run.scene, run.frameInterval);
    if (run.parameters.componentFlows) budget.emplace(run.out, run.scene, run.frameInterval);
  }
  MethodParameters parameters = run.parameters;
  if (!run.method.isIda() && outputs.checkpoints) {
    parameters.checkpoints.every = outputs.checkpointEvery;
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
  RunResult result;
  result.summary = runMethod(
      *run.scene.model, run.method, parameters,
      [&](const StepRecord& r) {
        if (history) {
          history->write(r);
          frames->write(r);
          solids->write(r);
          if (budget) budget->write(r);
        }
        if (outputs.observe) outputs.observe(r);
      },
      outputs.progress);
  if (!outputs.files) return result;
  history->finish(result.summary);
  frames->finish();
  solids->finish();
  if (budget) budget->finish();
  result.history = history->path();
  // like a checkpoint, a summary that cannot be written leaves the run's history standing
  try {
    writeAtomically((run.out / "summary.json").string(),
                    [&](std::ostream& stream) { stream << summaryJson(run, result.summary) << '\n'; });
  } catch (const std::runtime_error& error) {
    fmt::print(stderr, "metriplex: warning: {}\n", error.what());
  }
  return result;
}

std::string summaryJson(const PreparedRun& run, const RunSummary& s) {
  const MethodParameters& p = run.parameters;
  JsonObject summary;
  summary.add("scene", run.scene.name)
      .add("integrator", run.method.name)
      .add("thermal_variable", run.thermalVariable())
      .add("adaptive", p.adaptive && !run.method.isIda())
      .add("dt", p.dt)
      .add("t_end", p.tEnd)
      .add("status", statusOf(s))
      .add("steps", s.steps)
      .add("newton_iterations", s.newtonIterations)
      .add("factorizations", s.factorizations)
      .add("cutbacks", s.cutbacks)
      .add("rejected_steps", s.rejectedSteps)
      .add("linear_system", s.linearSystem)
      .add("wall_seconds", s.wallSeconds)
      .add("max_relative_energy_drift", s.maxEnergyBalanceError)
      .add("max_energy_drift", s.maxAbsoluteEnergyBalanceError)
      .add("min_entropy_production", s.minEntropyProduction);
  if (p.adaptive || run.method.isIda()) summary.add("rtol", p.relativeTolerance).add("atol", p.absoluteTolerance);
  if (s.ida)
    summary.add("ida", JsonObject()
                           .add("steps", s.ida->steps)
                           .add("residual_evaluations", s.ida->residualEvaluations)
                           .add("jacobian_evaluations", s.ida->jacobianEvaluations)
                           .add("nonlinear_iterations", s.ida->nonlinearIterations)
                           .add("error_test_failures", s.ida->errorTestFailures)
                           .add("convergence_failures", s.ida->convergenceFailures));
  if (s.failed)
    summary.add("failure", JsonObject().add("step", s.failedStep).add("time", s.failedTime).add("message", s.failure));
  if (s.interrupted) summary.add("interrupted", JsonObject().add("step", s.steps).add("time", s.interruptedTime));
  return summary.text();
}

}  // namespace mpx
