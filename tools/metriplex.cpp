// metriplex: run scenes with EEM and standard integrators from the command line.
// Exit codes: 0 success, 2 invalid input or arguments, 3 solver failure.
#include "history_csv.hpp"

#include "engine/ida_simulation.hpp"
#include "engine/input_error.hpp"
#include "models/scene/scene_loader.hpp"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <unistd.h>

#include <optional>
#include <sstream>

namespace {

using namespace mpx;

constexpr int kExitInvalidInput = 2;
constexpr int kExitSolverFailure = 3;

struct IntegratorChoice {
  bool ida;       // SUNDIALS IDA instead of a one-step scheme
  Scheme scheme;  // the one-step scheme otherwise
  std::optional<ThermalVariable> thermalVariable;  // empty: the scene's own
};

IntegratorChoice parseIntegrator(const std::string& name) {
  if (name == "eem") return {false, Scheme::Eem, std::nullopt};
  if (name == "eem-entropy") return {false, Scheme::Eem, ThermalVariable::Entropy};
  if (name == "eem-temperature") return {false, Scheme::Eem, ThermalVariable::Temperature};
  if (name == "midpoint") return {false, Scheme::Midpoint, std::nullopt};
  if (name == "trapezoidal") return {false, Scheme::Trapezoidal, std::nullopt};
  if (name == "ida") return {true, Scheme::Eem, std::nullopt};
  throw InputError("unknown integrator '" + name +
                   "' (choose eem, eem-entropy, eem-temperature, midpoint, trapezoidal, ida)");
}

struct RunRequest {
  std::string scene;
  std::string integrator;  // empty: the scene's default
  std::optional<double> dt, tEnd;
  std::string out;  // empty: out/<scene>-<integrator>
  // IDA only
  double relativeTolerance = 1e-6, absoluteTolerance = 1e-8;
  int maxOrder = 5;
  std::optional<double> outputStep;
};

struct RunResult {
  std::string integrator, variable;
  RunSummary summary;
  std::filesystem::path history;
};

void checkPositive(std::optional<double> value, const char* option) {
  if (value && !(*value > 0.0 && std::isfinite(*value)))
    throw InputError(fmt::format("option {} must be a positive number, got {}", option, *value));
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

// Validate everything, then run and write DIR/history.csv.
RunResult runScene(const RunRequest& request) {
  checkPositive(request.dt, "--dt");
  checkPositive(request.tEnd, "--t-end");
  checkPositive(request.relativeTolerance, "--rtol");
  checkPositive(request.absoluteTolerance, "--atol");
  checkPositive(request.outputStep, "--dt-out");
  if (request.maxOrder < 1 || request.maxOrder > 5)
    throw InputError(fmt::format("option --max-order must be 1 to 5, got {}", request.maxOrder));
  std::optional<IntegratorChoice> choice;
  if (!request.integrator.empty()) choice = parseIntegrator(request.integrator);
  CompiledScene scene = loadScene(request.scene, choice ? choice->thermalVariable : std::nullopt);
  const std::string integrator = request.integrator.empty() ? scene.settings.integrator : request.integrator;
  if (!choice) choice = parseIntegrator(integrator);

  const double dt = request.dt.value_or(scene.settings.dt);
  const double tEnd = request.tEnd.value_or(scene.settings.tEnd);

  const std::filesystem::path out =
      request.out.empty() ? std::filesystem::path("out") / (scene.settings.name + "-" + integrator)
                           : std::filesystem::path(request.out);
  std::filesystem::create_directories(out);
  HistoryCsv history(out, *scene.model);
  RunResult result{integrator,
                   scene.model->thermalVariable() == ThermalVariable::Entropy ? "entropy" : "temperature",
                   {}, history.path()};
  const StepSink write = [&](const StepRecord& r) { history.write(r); };
  const ProgressSink progress = progressBar(scene.settings.name + " " + integrator);
  if (choice->ida) {
    const IdaOptions options{request.relativeTolerance, request.absoluteTolerance, request.maxOrder,
                             request.outputStep.value_or(dt), tEnd};
    result.summary = simulateIda(*scene.model, options, write, progress);
  } else {
    result.summary = simulate(*scene.model, {choice->scheme, dt, tEnd, scene.settings.newton}, write, progress);
  }
  history.finish(result.summary);
  return result;
}

void printSummary(const RunResult& r, const RunRequest& request) {
  const RunSummary& s = r.summary;
  fmt::print("metriplex run {} --integrator {} (thermal variable: {})\n", request.scene, r.integrator, r.variable);
  fmt::print("  steps                    {}\n", s.steps);
  fmt::print("  newton iterations        {} ({:.2f} per step)\n", s.newtonIterations,
             s.steps ? static_cast<double>(s.newtonIterations) / s.steps : 0.0);
  if (s.ida)
    fmt::print("  IDA                      {} steps, {} residual evaluations, {} Jacobian evaluations, "
               "{} nonlinear iterations, {} error-test failures\n",
               s.ida->steps, s.ida->residualEvaluations, s.ida->jacobianEvaluations, s.ida->nonlinearIterations,
               s.ida->errorTestFailures);
  else
    fmt::print("  cut-backs                {}\n", s.cutbacks);
  fmt::print("  wall time                {:.3f} s\n", s.wallSeconds);
  fmt::print("  max rel. energy drift    {:.3e}  (|E + dissipated - external work - boundary heat - E0| / |E0|)\n",
             s.maxEnergyBalanceError);
  fmt::print("  min entropy increment    {:.3e}\n", s.minEntropyIncrement);
  fmt::print("  history                  {}\n", r.history.string());
}

int runCommand(const RunRequest& request) {
  const RunResult result = runScene(request);
  printSummary(result, request);
  if (!result.summary.failed) return 0;
  fmt::print(stderr, "metriplex: solver failure at step {} (t = {:.9g}): {}; history kept up to the last good step in {}\n",
             result.summary.failedStep, result.summary.failedTime, result.summary.failure, result.history.string());
  return kExitSolverFailure;
}

// Several integrators on one scene, side by side. A blow-up is a finding here, not an error.
int compareCommand(RunRequest base, const std::string& integrators) {
  std::vector<std::string> names;
  std::stringstream list(integrators);
  for (std::string name; std::getline(list, name, ',');) {
    parseIntegrator(name);  // reject a bad name before any run
    names.push_back(name);
  }
  const std::filesystem::path root =
      base.out.empty() ? std::filesystem::path("out") / (loadScene(base.scene).settings.name + "-compare")
                     : std::filesystem::path(base.out);
  fmt::print("{:<16} {:>8} {:>12} {:>10} {:>16} {:>16}  {}\n", "integrator", "steps", "newton/step", "wall [s]",
             "max energy drift", "min dS per step", "status");
  for (const std::string& name : names) {
    RunRequest request = base;
    request.integrator = name;
    request.out = (root / name).string();
    const RunResult r = runScene(request);
    const RunSummary& s = r.summary;
    const std::string status =
        s.failed ? fmt::format("failed at step {} (t = {:.6g}): {}", s.failedStep, s.failedTime, s.failure) : "ok";
    fmt::print("{:<16} {:>8} {:>12.2f} {:>10.3f} {:>16.3e} {:>16.3e}  {}\n", name, s.steps,
               s.steps ? static_cast<double>(s.newtonIterations) / s.steps : 0.0, s.wallSeconds,
               s.maxEnergyBalanceError, s.minEntropyIncrement, status);
  }
  fmt::print("histories in {}/<integrator>/history.csv\n", root.string());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Metriplex: flexible multibody dynamics with dissipation, integrated with "
               "Energy-Entropy-Momentum (EEM) and standard methods.\n"
               "Exit codes: 0 success, 2 invalid input or arguments, 3 solver failure."};
  app.require_subcommand(1);

  RunRequest request;
  std::string integrators = "eem,midpoint";
  auto addCommon = [&](CLI::App* command) {
    command->add_option("SCENE", request.scene, "scene file (XML, see docs/scene-format.md)")->required();
    command->add_option("--dt", request.dt, "time step (default: the scene's simulation dt)");
    command->add_option("--t-end", request.tEnd, "end time (default: the scene's simulation t_end)");
  };
  CLI::App* run = app.add_subcommand("run", "run one scene with one integrator; writes DIR/history.csv");
  addCommon(run);
  run->add_option("--integrator", request.integrator,
                  "eem (the scene's thermal variable), eem-entropy, eem-temperature, midpoint, trapezoidal, ida "
                  "(default: the scene's simulation integrator)");
  run->add_option("--out", request.out, "output directory (default: out/<scene name>-<integrator>)");
  run->add_option("--rtol", request.relativeTolerance, "ida: relative tolerance")->capture_default_str();
  run->add_option("--atol", request.absoluteTolerance, "ida: absolute tolerance, times each dof's scale")
      ->capture_default_str();
  run->add_option("--max-order", request.maxOrder, "ida: maximum BDF order (1-5)")->capture_default_str();
  run->add_option("--dt-out", request.outputStep, "ida: output interval of history rows (default: --dt)");
  CLI::App* compare = app.add_subcommand("compare", "run one scene with several integrators and tabulate "
                                                    "energy drift, entropy and cost side by side");
  addCommon(compare);
  compare->add_option("--integrators", integrators, "comma-separated integrators")->capture_default_str();
  compare->add_option("--out", request.out, "output directory (default: out/<scene name>-compare)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kExitInvalidInput;
  }
  try {
    return run->parsed() ? runCommand(request) : compareCommand(request, integrators);
  } catch (const InputError& e) {
    fmt::print(stderr, "metriplex: {}\n", e.what());
    return kExitInvalidInput;
  } catch (const std::filesystem::filesystem_error& e) {
    fmt::print(stderr, "metriplex: {}\n", e.what());
    return kExitInvalidInput;
  }
}
