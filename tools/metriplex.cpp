// metriplex: run scenes with EEM and standard integrators from the command line.
// Exit codes: 0 success, 2 invalid input or arguments, 3 solver failure.
#include "tools/commands.hpp"
#include "tools/output/history_plots.hpp"

#include "engine/core/input_error.hpp"
#include "engine/stepping/method.hpp"
#include "engine/stepping/simulation.hpp"

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <csignal>
#include <filesystem>

namespace {

using namespace mpx;

extern "C" void stopAtNextStep(int signal) {
  requestStop();
  std::signal(signal, SIG_DFL);
}

std::vector<std::string> splitNames(const std::string& list) {
  std::vector<std::string> names;
  if (list.empty()) return names;  // the command says it needs one
  std::size_t start = 0;
  for (std::size_t comma; start <= list.size(); start = comma + 1) {
    comma = std::min(list.find(',', start), list.size());
    const std::string name = list.substr(start, comma - start);
    // an empty name would silently stand for the scene's own integrator; a repeated one would
    // run twice into one directory
    if (name.empty()) throw InputError("option --integrators: an empty name in '" + list.substr(0, 64) + "'");
    if (std::find(names.begin(), names.end(), name) != names.end())
      throw InputError("option --integrators: '" + name.substr(0, 64) + "' is named twice");
    names.push_back(name);
  }
  return names;
}

// An option given with an empty value, e.g. --out "", would silently take its default.
void refuseEmpty(const CLI::App& command, const char* option, const std::string& value) {
  if (command.count(option) > 0 && value.empty())
    throw InputError(std::string("option ") + option + ": an empty value");
}

// Options every subcommand shares.
void addSceneOptions(CLI::App* command, RunRequest& request) {
  command->add_option("SCENE", request.scene, "scene file (XML) or a robot's .urdf, see docs/scene-format.md")
      ->required();
  command->add_option("--t-end", request.tEnd, "end time (default: the scene's simulation t_end)");
}

// run and compare: joint stops of a .urdf scene.
void addUrdfLimitsOption(CLI::App* command, RunRequest& request) {
  command->add_flag("--urdf-limits", request.urdfLimits,
                    "a .urdf scene: joint stops at its position limits (as <urdf limits=\"true\"> in an XML scene)");
}

// Adaptive steps of the one-step integrators and the tolerances they share with IDA.
void addToleranceOptions(CLI::App* command, RunRequest& request) {
  command->add_flag(
      "--adaptive", request.adaptive,
      "eem, eem4, midpoint, trapezoidal: adaptive steps to --rtol/--atol, --dt the first step (default: the "
      "scene's simulation adaptive)");
  command->add_option("--rtol", request.relativeTolerance,
                      "ida and adaptive steps: relative tolerance (default: the scene's simulation rtol, 1e-6)");
  command->add_option("--atol", request.absoluteTolerance,
                      "ida and adaptive steps: absolute tolerance, times each dof's scale (default: --rtol when given, "
                      "else the scene's atol, else its rtol)");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Metriplex: flexible multibody dynamics with dissipation, integrated with "
      "Energy-Entropy-Momentum (EEM) and standard methods.\n"
      "Exit codes: 0 success, 2 invalid input or arguments, 3 solver failure, 4 interrupted by SIGINT or SIGTERM "
      "(stopped at a step boundary, history kept)."};
  app.require_subcommand(1);

  RunRequest request;
  std::string integrators = "eem,midpoint";
  CLI::App* run = app.add_subcommand("run", "run one scene with one integrator; writes DIR/history.csv");
  addSceneOptions(run, request);
  run->add_option("--integrator", request.integrator,
                  std::string(kMethodNames) +
                      "; eem takes the scene's thermal variable (default: the scene's "
                      "simulation integrator)");
  run->add_option("--dt", request.dt, "time step (default: the scene's simulation dt)");
  run->add_option("--out", request.out, "output directory (default: out/<scene name>-<integrator>)");
  addToleranceOptions(run, request);
  addUrdfLimitsOption(run, request);
  run->add_option("--max-order", request.maxOrder, "ida: maximum BDF order (1-5; default: 5, or K for ida-bdfK)");
  run->add_flag("--sundials-klu", request.sundialsKlu,
                "ida: factorise the whole Newton matrix with SUNDIALS' KLU instead of Metriplex's solver (velocities "
                "eliminated, then a dense LU, KLU or UMFPACK by size)");
  run->add_option("--dt-out", request.outputStep, "ida: output interval of history rows (default: --dt)");
  run->add_option("--checkpoint-every", request.checkpointEvery,
                  "one-step integrators: write DIR/checkpoint.txt every N steps (always at SIGINT/SIGTERM)");
  run->add_option("--restart", request.restart,
                  "one-step integrators: continue the run from a checkpoint file; its history starts at the "
                  "checkpoint's step");
  run->add_flag(
      "--budget", request.budget,
      "one-step integrators (not ida): write DIR/budget.csv and budget.png, energy and entropy per scene element");
  run->add_option("--output-interval", request.frameInterval,
                  "interval of bodies.csv, joints.csv and budget.csv rows and of solid frames (.vtu) (default: every "
                  "history row)");

  CLI::App* compare = app.add_subcommand("compare",
                                         "run one scene with several integrators and tabulate "
                                         "energy drift, entropy and cost side by side");
  addSceneOptions(compare, request);
  compare->add_option("--dt", request.dt, "time step (default: the scene's simulation dt)");
  compare->add_option("--integrators", integrators, "comma-separated integrators")->capture_default_str();
  addToleranceOptions(compare, request);
  addUrdfLimitsOption(compare, request);
  compare->add_option("--out", request.out, "output directory (default: out/<scene name>-compare)");

  BenchRequest bench;
  std::string benchIntegrators = "eem,midpoint,trapezoidal,ida";
  CLI::App* benchCommandLine = app.add_subcommand(
      "bench",
      "work-precision sweep: one-step integrators over steps, IDA and adaptive steps over tolerances, "
      "against a cached reference (IDA at rtol 1e-12, or EEM at a 64th of the scene's step where "
      "IDA cannot run the scene); writes work_precision.csv and PNG plots");
  addSceneOptions(benchCommandLine, request);
  benchCommandLine->add_option("--integrators", benchIntegrators, "comma-separated integrators")->capture_default_str();
  benchCommandLine
      ->add_option("--dts", bench.steps, "steps of the one-step integrators (default: scene dt x 2 .. 1/16)")
      ->delimiter(',');
  benchCommandLine
      ->add_option("--rtols", bench.tolerances,
                   "relative tolerances of IDA and the adaptive schemes (default: 1e-3 .. 1e-10)")
      ->delimiter(',');
  benchCommandLine->add_option("--repeats", bench.repeats, "repeats per run (median CPU time)")->capture_default_str();
  benchCommandLine->add_option("--out", request.out, "output directory (default: out/<scene name>-bench)");

  std::string plotDirectory;
  CLI::App* plot = app.add_subcommand(
      "plot", "render DIR/history.csv to PNG: energy.png, entropy.png, temperatures.png, constraint_violation.png");
  plot->add_option("DIR", plotDirectory, "a run's output directory (metriplex run --out)")->required();

  // CLI11 reports a misspelt subcommand only as "A subcommand is required": name it
  const std::string first = argc > 1 ? argv[1] : "";
  const auto named = app.get_subcommands([&](const CLI::App* command) { return command->get_name() == first; });
  if (!first.empty() && first[0] != '-' && named.empty()) {
    fmt::print(stderr, "metriplex: unknown subcommand '{}' (choose run, compare, bench or plot; see --help)\n", first);
    return kExitInvalidInput;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kExitInvalidInput;
  }
  // SIGINT and SIGTERM stop a run at its next step boundary, with its history well formed; a
  // second one (while a scene loads, say) ends the program at once
  for (const int signal : {SIGINT, SIGTERM}) std::signal(signal, stopAtNextStep);
  try {
    for (const CLI::App* command : {run, compare, benchCommandLine}) refuseEmpty(*command, "--out", request.out);
    refuseEmpty(*run, "--restart", request.restart);
    if (run->parsed()) return runCommand(request);
    if (compare->parsed()) return compareCommand(request, splitNames(integrators));
    if (plot->parsed()) {
      for (const std::filesystem::path& picture : renderHistoryPlots(plotDirectory))
        fmt::print("{}\n", picture.string());
      return 0;
    }
    bench.scene = request.scene;
    bench.tEnd = request.tEnd;
    bench.out = request.out;
    bench.integrators = splitNames(benchIntegrators);
    return benchCommand(bench);
  } catch (const InputError& e) {
    fmt::print(stderr, "metriplex: {}\n", e.what());
    return kExitInvalidInput;
  } catch (const RunInterrupted& e) {
    fmt::print(stderr, "metriplex: {}\n", e.what());
    return kExitInterrupted;
  } catch (const std::filesystem::filesystem_error& e) {
    fmt::print(stderr, "metriplex: {}\n", e.what());
    return kExitInvalidInput;
  } catch (const std::runtime_error& e) {
    fmt::print(stderr, "metriplex: {}\n", e.what());
    return kExitSolverFailure;
  }
}
