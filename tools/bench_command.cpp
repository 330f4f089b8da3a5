// metriplex bench: a work-precision sweep of one scene. One-step schemes over a list of steps,
// IDA and adaptive one-step schemes over a list of tolerances, each against one cached
// reference solution (IDA at rtol 1e-12, or EEM at a 64th of the scene's step where IDA cannot
// run the scene): positions and temperatures at t_end, and the energy at the end of loading
// (the last load breakpoint before t_end).
#include "tools/commands.hpp"
#include "tools/output/plots.hpp"

#include "engine/core/input_error.hpp"
#include "engine/stepping/method.hpp"
#include "models/scene/scene_loader.hpp"

#include <fmt/format.h>
#include <fmt/os.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace mpx {

namespace {

constexpr double kReferenceTolerance = 1e-12;

// What is compared with the reference: the final positions and temperatures, and the energy
// when the loads end (NaN for a scene without a load breakpoint before t_end).
struct FinalState {
  Eigen::VectorXd positions;
  std::vector<double> temperatures;
  double loadEndEnergy = NAN;
};

// The last load breakpoint before tEnd (NaN if none): after it the loads are constant.
double loadEnd(const Model& model, double tEnd) {
  const std::vector<double>& kinks = model.loadBreakpoints();
  const auto last = std::find_if(kinks.rbegin(), kinks.rend(), [&](double t) { return t > 0.0 && t < tEnd; });
  return last == kinks.rend() ? NAN : *last;
}

struct BenchRun {
  std::string integrator;
  double dt = 0.0, rtol = 0.0;  // one of the two is the sweep parameter
  double cpuSeconds = 0.0;
  RunSummary summary;
  FinalState final;
  int entropyViolations = 0;
  double error = 0.0;          // relative, positions and temperatures
  double positionError = 0.0;  // max |x - x_ref| over the position dofs
  double energyError = NAN;    // |E - E_ref| / |E_ref| at the end of loading
  std::string status;
  std::vector<SeriesPoint> series;
};

FinalState finalStateOf(const Model& model, const Eigen::VectorXd& state, const Measures& measures) {
  return {state.segment(model.layout().offset(Block::Position), model.layout().size(Block::Position)),
          measures.nodeTemperature};
}

// max of the relative position and temperature errors against the reference
double relativeError(const FinalState& run, const FinalState& reference) {
  double error = (run.positions - reference.positions).lpNorm<Eigen::Infinity>() /
                 std::max(reference.positions.lpNorm<Eigen::Infinity>(), 1e-300);
  double largest = 0.0, deviation = 0.0;
  for (std::size_t i = 0; i < reference.temperatures.size(); ++i) {
    largest = std::max(largest, std::abs(reference.temperatures[i]));
    deviation = std::max(deviation, std::abs(run.temperatures[i] - reference.temperatures[i]));
  }
  if (largest > 0.0) error = std::max(error, deviation / largest);
  return std::isfinite(error) ? error : INFINITY;
}

// One run, repeated for a median CPU time; keeps the last repeat's results.
BenchRun measure(const Model& model, const Method& method, const MethodParameters& parameters, int repeats,
                 bool keepSeries) {
  const double loadEndTime = loadEnd(model, parameters.tEnd);
  BenchRun run;
  run.integrator = method.name;
  std::vector<double> cpu;
  for (int r = 0; r < repeats; ++r) {
    Measures last;
    Eigen::VectorXd lastState;
    double loadEndEnergy = NAN;
    EnergyBalance balance(0.0);
    double initialEntropy = 0.0, previousEntropy = 0.0;
    run.entropyViolations = 0;
    run.series.clear();
    const std::clock_t start = std::clock();
    run.summary = runMethod(model, method, parameters, [&](const StepRecord& record) {
      const Measures& m = *record.measures;
      if (record.step == 0) balance = EnergyBalance(m.energy), initialEntropy = previousEntropy = m.entropy;
      if (m.entropy < previousEntropy - 1e-14 * std::abs(m.entropy)) ++run.entropyViolations;
      previousEntropy = m.entropy;
      if (keepSeries) {
        const double error = balance.relativeError(m.energy, record.crossed.dissipated, record.crossed.externalWork,
                                                   record.crossed.boundaryHeat);
        run.series.push_back({record.time, error, m.entropy - initialEntropy});
      }
      last = m;
      lastState = *record.state;
      if (std::isnan(loadEndEnergy) && record.time >= loadEndTime - 1e-9 * parameters.tEnd) loadEndEnergy = m.energy;
    });
    if (run.summary.interrupted) throw RunInterrupted();
    cpu.push_back(static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC);
    run.final = finalStateOf(model, lastState, last);
    run.final.loadEndEnergy = loadEndEnergy;
  }
  std::sort(cpu.begin(), cpu.end());
  run.cpuSeconds = cpu[cpu.size() / 2];
  return run;
}

// IDA's output interval: about t_end / 100, a divisor of the end of loading where there is one.
double idaOutputStep(const Model& model, double tEnd) {
  const double end = loadEnd(model, tEnd);
  return std::isnan(end) ? tEnd / 100 : end / std::ceil(end / (tEnd / 100));
}

// How the reference is computed: IDA at a tight tolerance, or, for a scene IDA cannot run (a
// prescribed displacement has no rate form), EEM at a 64th of the scene's step, with the run at
// a 32nd beside it to show that it has converged.
struct Referee {
  bool ida = true;
  double eemStep = 0.0;
  NewtonSettings newton;
  std::string describe() const {
    return ida ? fmt::format("ida rtol {:g}", kReferenceTolerance) : fmt::format("eem dt {:g}", eemStep);
  }
};

BenchRun referenceRun(const Model& model, const Referee& referee, double tEnd, double eemStep) {
  MethodParameters parameters;
  parameters.tEnd = tEnd;
  if (referee.ida) {
    parameters.dt = idaOutputStep(model, tEnd);
    parameters.relativeTolerance = kReferenceTolerance;
    parameters.absoluteTolerance = kReferenceTolerance;
  } else {
    parameters.dt = eemStep;
    parameters.newton = referee.newton;
  }
  BenchRun run = measure(model, *methodByName(referee.ida ? "ida" : "eem"), parameters, 1, false);
  if (run.summary.failed)
    throw std::runtime_error("the reference run (" + referee.describe() + ") failed: " + run.summary.failure);
  return run;
}

// Reference final state: computed once per scene text, end time and referee, cached in
// DIR/reference.csv.
FinalState reference(const Model& model, const Referee& referee, const std::string& sceneText, double tEnd,
                     const std::filesystem::path& dir) {
  const std::string key =
      fmt::format("{} t_end {:.17g} scene {}", referee.describe(), tEnd, std::hash<std::string>{}(sceneText));
  const std::filesystem::path file = dir / "reference.csv";
  FinalState cached;
  std::ifstream in(file);
  std::string line;
  if (std::getline(in, line) && line == "# " + key) {
    // strtod, not >>, so that the "nan" of a scene without loads reads back; a value that does
    // not read whole, or a state that is not finite, leaves the cache to be computed again
    std::vector<double> values;
    bool whole = true;
    for (std::string value; std::getline(in, value, ',');) {
      if (!value.empty() && value.back() == '\n') value.pop_back();
      char* end = nullptr;
      values.push_back(std::strtod(value.c_str(), &end));
      whole = whole && !value.empty() && end == value.c_str() + value.size();
    }
    const Eigen::Index positions = model.layout().size(Block::Position);
    const bool finite =
        !values.empty() && std::all_of(values.begin(), values.end() - 1, [](double v) { return std::isfinite(v); });
    if (whole && finite && values.size() == positions + model.thermalNodeNames().size() + 1) {
      cached.positions = Eigen::Map<Eigen::VectorXd>(values.data(), positions);
      cached.temperatures.assign(values.begin() + positions, values.end() - 1);
      cached.loadEndEnergy = values.back();
      fmt::print("reference: cached in {}\n", file.string());
      return cached;
    }
  }
  const BenchRun run = referenceRun(model, referee, tEnd, referee.eemStep);
  auto out = fmt::output_file(file.string());
  out.print("# {}\n", key);
  std::string row;
  for (double v : run.final.positions) row += fmt::format("{}{:.17g}", row.empty() ? "" : ",", v);
  for (double v : run.final.temperatures) row += fmt::format(",{:.17g}", v);
  out.print("{},{:.17g}\n", row, run.final.loadEndEnergy);
  fmt::print("reference: {} ({:.2f} s CPU), written to {}\n", referee.describe(), run.cpuSeconds, file.string());
  if (!referee.ida) {
    const BenchRun coarser = referenceRun(model, referee, tEnd, 2.0 * referee.eemStep);
    fmt::print(
        "reference: IDA cannot run this scene; EEM at dt {:g} differs from EEM at dt {:g} by {:.3e} "
        "(relative, at t_end): the reference's own error is about a third of that (order 2)\n",
        referee.eemStep, 2.0 * referee.eemStep, relativeError(coarser.final, run.final));
  }
  return run.final;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the scene file");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

void writeCsv(const std::filesystem::path& file, const std::vector<BenchRun>& runs) {
  auto out = fmt::output_file(file.string());
  out.print(
      "integrator,dt,rtol,cpu_seconds,steps,newton_iterations,ida_steps,ida_residual_evaluations,"
      "ida_jacobian_evaluations,ida_nonlinear_iterations,ida_error_test_failures,error,position_error,"
      "load_end_energy_error,energy_drift,entropy_violations,rejected_steps,status\n");
  for (const BenchRun& r : runs) {
    const IdaStatistics ida = r.summary.ida.value_or(IdaStatistics{});
    out.print("{},{:g},{:g},{:.6g},{},{},{},{},{},{},{},{:.6e},{:.6e},{:.6e},{:.6e},{},{},{}\n", r.integrator, r.dt,
              r.rtol, r.cpuSeconds, r.summary.steps, r.summary.newtonIterations, ida.steps, ida.residualEvaluations,
              ida.jacobianEvaluations, ida.nonlinearIterations, ida.errorTestFailures, r.error, r.positionError,
              r.energyError, r.summary.maxEnergyBalanceError, r.entropyViolations, r.summary.rejectedSteps, r.status);
  }
}

}  // namespace

int benchCommand(const BenchRequest& request) {
  // validate everything before anything is written
  if (request.repeats < 1) throw InputError("option --repeats must be at least 1");
  if (request.integrators.empty()) throw InputError("option --integrators: no integrator given");
  for (double v : request.steps)
    if (!(v > 0.0 && std::isfinite(v)))
      throw InputError(fmt::format("option --dts: steps must be positive, got {}", v));
  for (double v : request.tolerances)
    if (!(v > 0.0 && v < 1.0)) throw InputError(fmt::format("option --rtols: tolerances must be in (0, 1), got {}", v));
  if (request.tEnd && !(*request.tEnd > 0.0)) throw InputError("option --t-end must be positive");
  const CompiledScene own = loadScene(request.scene);
  const SceneSettings& settings = own.settings;
  // a scene IDA cannot run is measured against a fine EEM run, and IDA leaves the sweep
  Referee referee{true, settings.dt / 64, settings.newton};
  std::string idaRefusal;
  try {
    checkMethodSupports(*methodByName("ida"), *own.model, request.scene);
  } catch (const InputError& refusal) {
    referee.ida = false;
    idaRefusal = refusal.what();
  }
  std::vector<Method> methods;
  for (const std::string& name : request.integrators) {
    const std::optional<Method> method = methodByName(name);
    if (!method) throw InputError(fmt::format("unknown integrator '{}' (choose {})", name, kMethodNames));
    if (method->isIda() && !referee.ida) {
      fmt::print("ida left out: {}\n", idaRefusal);
      continue;
    }
    if (method->scheme == Scheme::Eem4) {
      try {
        checkMethodSupports(*method, *own.model, request.scene);
      } catch (const InputError& refusal) {
        fmt::print("{} left out: {}\n", method->name, refusal.what());
        continue;
      }
    }
    methods.push_back(*method);
  }
  if (methods.empty()) throw InputError("option --integrators: nothing to run on this scene: " + idaRefusal);
  const std::string sceneText = readFile(request.scene);
  std::map<std::string, CompiledScene> scenes;  // per method name: its thermal variable
  for (const Method& method : methods) scenes.emplace(method.name, loadScene(request.scene, method.thermalVariable));
  const double tEnd = request.tEnd.value_or(settings.tEnd);
  std::vector<double> steps = request.steps;
  if (steps.empty())
    for (double factor : {2.0, 1.0, 0.5, 0.25, 0.125, 0.0625}) steps.push_back(factor * settings.dt);
  for (double dt : steps) checkStepCount(tEnd, dt, "option --dts");
  std::vector<double> tolerances = request.tolerances;
  if (tolerances.empty()) tolerances = {1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10};
  const std::filesystem::path out =
      request.out.empty() ? std::filesystem::path("out") / (own.name + "-bench") : std::filesystem::path(request.out);

  std::error_code error;
  std::filesystem::create_directories(out, error);
  if (error)
    throw InputError(fmt::format("option --out: cannot create the directory {}: {}", out.string(), error.message()));
  const FinalState referenceState = reference(*own.model, referee, sceneText, tEnd, out);

  // representative runs for the time series: the scene's step, rtol 1e-6 (or the middle ones)
  const double seriesStep = std::count(steps.begin(), steps.end(), settings.dt) ? settings.dt : steps[steps.size() / 2];
  const double seriesTolerance =
      std::count(tolerances.begin(), tolerances.end(), 1e-6) ? 1e-6 : tolerances[tolerances.size() / 2];
  std::vector<BenchRun> runs;
  for (const Method& method : methods) {
    const Model& model = *scenes.at(method.name).model;
    for (double value : method.takesTolerance() ? tolerances : steps) {
      MethodParameters parameters;
      parameters.tEnd = tEnd;
      parameters.newton = settings.newton;
      parameters.dt = method.isIda() ? idaOutputStep(model, tEnd) : method.adaptive ? settings.dt : value;
      parameters.relativeTolerance = value;
      parameters.absoluteTolerance = value;
      const bool keepSeries = value == (method.takesTolerance() ? seriesTolerance : seriesStep);
      BenchRun run = measure(model, method, parameters, request.repeats, keepSeries);
      (method.takesTolerance() ? run.rtol : run.dt) = value;
      run.error = run.summary.failed ? INFINITY : relativeError(run.final, referenceState);
      run.positionError =
          run.summary.failed ? INFINITY : (run.final.positions - referenceState.positions).lpNorm<Eigen::Infinity>();
      run.energyError =
          std::abs(run.final.loadEndEnergy - referenceState.loadEndEnergy) / std::abs(referenceState.loadEndEnergy);
      run.status = run.summary.failed                                                                ? "failed"
                   : !(run.summary.maxEnergyBalanceError < kBlowUpEnergyError) || !(run.error < 1.0) ? "blew-up"
                                                                                                     : "ok";
      fmt::print(
          "{:<20} {:>10} {:>10.4g} s CPU {:>7} steps  error {:.3e}  position error {:.3e}  energy at load end "
          "{:.3e}  energy drift {:.3e}  {}\n",
          method.name, fmt::format(method.takesTolerance() ? "rtol {:g}" : "dt {:g}", value), run.cpuSeconds,
          run.summary.steps, run.error, run.positionError, run.energyError, run.summary.maxEnergyBalanceError,
          run.status);
      runs.push_back(std::move(run));
    }
  }
  writeCsv(out / "work_precision.csv", runs);

  // plots: work-precision of the ok runs, energy error and entropy of the representative ones
  std::vector<WorkPrecisionCurve> workPrecision;
  std::vector<TimeSeries> series;
  for (const Method& method : methods) {
    WorkPrecisionCurve curve{method.name, {}};
    for (const BenchRun& r : runs)
      if (r.integrator == method.name && r.status == "ok")
        curve.points.push_back({r.cpuSeconds, r.error, r.energyError});
    workPrecision.push_back(std::move(curve));
    for (const BenchRun& r : runs)
      if (r.integrator == method.name && !r.series.empty())
        series.push_back({fmt::format(method.takesTolerance() ? "{} rtol {:g}" : "{} dt {:g}", method.name,
                                      method.takesTolerance() ? r.rtol : r.dt),
                          r.series});
  }
  renderPlots(out, own.name, tEnd, workPrecision, series);
  fmt::print("wrote {}/work_precision.csv, work_precision.png, {}energy_error.png, entropy.png\n", out.string(),
             std::isnan(referenceState.loadEndEnergy) ? "" : "work_precision_energy.png, ");
  return 0;
}

}  // namespace mpx
