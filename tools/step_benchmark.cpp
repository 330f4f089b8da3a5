// metriplex_step_benchmark: cost of one integrator step along a real trajectory (time, Newton
// iterations, cut-backs) for the benchmark scenes, generated chains of thermo-springs and of
// rigid links, and the tumbling L-block by mesh level (with the step split into assembly and
// linear solve).
// Reproduce and read the figures with docs/performance.md.
#include "engine/linear/condensed_solver.hpp"
#include "engine/stepping/integrator.hpp"
#include "models/scene/scene_loader.hpp"

#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <utility>

namespace {

using namespace mpx;

// A scene compiled in a chosen thermal variable (empty: the scene's own).
using SceneSource = std::function<CompiledScene(std::optional<ThermalVariable>)>;

// The scenes shipped in scenes/ are read from the source tree.
SceneSource sceneFile(const std::string& file) {
  return [file](std::optional<ThermalVariable> variable) {
    return loadScene(std::string(METRIPLEX_SCENES_DIR) + "/" + file, variable);
  };
}

// Scenes generated in code are built as a SceneSpec (no XML text) and compiled on demand.
SceneSource sceneSpec(SceneSpec scene) {
  return [scene = std::move(scene)](std::optional<ThermalVariable> variable) { return compileScene(scene, variable); };
}

// A spec with the run settings every generated scene shares.
SceneSpec generatedScene(const std::string& name, double dt, double tEnd) {
  SceneSpec scene;
  scene.name = scene.label = name;
  scene.settings.dt = dt;
  scene.settings.tEnd = tEnd;
  return scene;
}

// A chain fixed to an anchor at the origin: masses along x at spacing 1.1 (springs pre-
// stretched by 0.1) with a transverse velocity pattern, a thermo-spring between consecutive
// points, temperatures varying along the chain and heat links between neighbouring springs.
SceneSpec thermoSpringChain(int masses, double dt) {
  SceneSpec scene = generatedScene("thermo_spring_chain", dt, 100);
  scene.settings.thermalVariable = ThermalVariable::Entropy;
  scene.add("anchor", {{"name", "origin"}, {"position", Vec3::Zero()}});
  const auto point = [](int i) { return i == 0 ? std::string("origin") : "m" + std::to_string(i); };
  for (int i = 1; i <= masses; ++i) {
    const std::string spring = "s" + std::to_string(i);
    scene.add("mass", {{"name", point(i)},
                       {"mass", 1.0},
                       {"position", Vec3(1.1 * i, 0, 0)},
                       {"velocity", Vec3(0, 0.2 * std::sin(0.3 * i), 0.1 * std::cos(0.7 * i))}});
    scene.add("thermo_spring", {{"name", spring},
                                {"a", point(i - 1)},
                                {"b", point(i)},
                                {"stiffness", 1.0},
                                {"coupling", 1.0},
                                {"rest_length", 1.0},
                                {"heat_capacity", 1.0},
                                {"reference_temperature", 1.0},
                                {"temperature", 1.0 + 0.5 * std::sin(i)}});
    if (i > 1)
      scene.add("heat_link", {{"name", "h" + std::to_string(i)},
                              {"a", "s" + std::to_string(i - 1)},
                              {"b", spring},
                              {"conductivity", 1.0}});
  }
  return scene;
}

// A chain of rigid links hinged to an anchor at the origin, released from rest horizontal in
// gravity: link i (1 kg, a 0.5 x 0.05 x 0.05 m box) is centred at (0.25 + 0.5 i, 0, 0) and
// joined to its predecessor by a revolute joint about y at their common end; `enforcement`
// and `stiffness` are the scene's constraint defaults.
SceneSpec rigidChain(int links, Enforcement enforcement, double stiffness, double dt) {
  const double mass = 1.0, length = 0.5, width = 0.05;
  const double axial = mass * (width * width + width * width) / 12;
  const double transverse = mass * (length * length + width * width) / 12;
  SceneSpec scene = generatedScene("rigid_chain", dt, 100);
  scene.constraints = {enforcement, stiffness};
  scene.gravity = Vec3(0, 0, -9.81);
  scene.add("anchor", {{"name", "origin"}, {"position", Vec3::Zero()}});
  const auto link = [](int i) { return i < 0 ? std::string("origin") : "l" + std::to_string(i); };
  for (int i = 0; i < links; ++i) {
    scene.add("body", {{"name", link(i)},
                       {"mass", mass},
                       {"inertia", Vec3(axial, transverse, transverse)},
                       {"position", Vec3(length * (i + 0.5), 0, 0)}});
    scene.add("joint", {{"name", "j" + std::to_string(i)},
                        {"type", "revolute"},
                        {"a", link(i - 1)},
                        {"b", link(i)},
                        {"anchor", Vec3(length * i, 0, 0)},
                        {"axis", Vec3::UnitY()}});
  }
  return scene;
}

// The tumbling L-block of scenes/lblock_elastic.xml (Neo-Hooke, two opposite dead tractions
// with the hat profile of period 5) on mesh level `level`; Viscoelastic adds the Maxwell branch
// of scenes/lblock_viscoelastic.xml, Thermoelastic the thermal field of
// scenes/lblock_thermoelastic.xml (same elastic constants, so only the thermal part differs).
enum class LBlockVariant { Elastic, Viscoelastic, Thermoelastic };
// Full Newton (a factorisation per iteration), or the simplified Newton the elastic and
// viscoelastic L-block scenes ask for (<solver reuse_contraction="0.25"/>), with the tangent's LU or, on large
// systems, the Cholesky factor of its symmetric part (<solver symmetric_factorisation>).
enum class LBlockNewton { Full, Simplified, SimplifiedSymmetric };

SceneSpec lblock(int level, LBlockVariant variant, double dt, LBlockNewton newton) {
  SceneSpec scene = generatedScene("lblock", dt, 50);
  if (newton != LBlockNewton::Full) scene.settings.newton.reuseContraction = 0.25;
  scene.settings.newton.symmetricFactorisation = newton == LBlockNewton::SimplifiedSymmetric;
  ElementSpec& block = scene.add("solid", {{"name", "block"},
                                           {"mesh", "lblock"},
                                           {"level", level},
                                           {"material", "neo_hooke"},
                                           {"young", 2.26115e3},
                                           {"poisson", 0.395469},
                                           {"density", 10.0}});
  if (variant == LBlockVariant::Viscoelastic)
    block.set("branch_lambda", 227.2).set("branch_mu", 49.875).set("viscosity", 100.0);
  if (variant == LBlockVariant::Thermoelastic) {
    block.set("heat_capacity", 100.0).set("conductivity", 10.0).set("expansion", 2.233e-4);
    for (const auto& [surface, temperature] : {std::pair{"load_y10", 313.15}, std::pair{"load_x6", 273.15}})
      scene.add("initial_temperature", {{"solid", "block"}, {"surface", surface}, {"temperature", temperature}});
  }
  for (const auto& [name, surface, sign] :
       {std::tuple{"push_top", "load_y10", 1.0}, std::tuple{"push_side", "load_x6", -1.0}})
    scene.add("traction", {{"name", name},
                           {"solid", "block"},
                           {"surface", surface},
                           {"total_force", Vec3(256, 512, 768) * sign},
                           {"profile", "hat"},
                           {"period", 5.0}});
  return scene;
}

// One trajectory of a scene at a fixed dt: each step advances z at time t into zNext, which
// then becomes z. The integrator and both states exist before any step is timed.
class Trajectory {
 public:
  Trajectory(const CompiledScene& scene, Scheme scheme, Eigen::VectorXd z, double t, double dt)
      : dt_(dt), integrator_(*scene.model, scheme, scene.settings.newton), z_(std::move(z)), zNext_(z_.size()), t_(t) {}

  // One step; false (see failure()) if Newton failed after all cut-backs.
  bool step() {
    const StepOutcome outcome = integrator_.advance(z_, t_, dt_, zNext_);
    if (!outcome.converged) {
      failure_ = "step failed at t = " + std::to_string(t_) + ": " + outcome.failure;
      return false;
    }
    newtonIterations_ += outcome.iterations;
    factorizations_ += outcome.factorizations;
    cutbacks_ += outcome.cutbacks;
    z_.swap(zNext_);
    t_ += dt_;
    return true;
  }
  // Start again from z at time t with steps of dt (the integrator, its LU analysed, is kept).
  void restart(const Eigen::VectorXd& z, double t, double dt) {
    z_ = z;
    t_ = t;
    dt_ = dt;
    newtonIterations_ = factorizations_ = cutbacks_ = 0;
    failure_.clear();
  }
  // Step on until t reaches `until` (within half a step).
  bool stepTo(double until) {
    while (t_ < until - 0.5 * dt_)
      if (!step()) return false;
    return true;
  }

  // Newton iterations, factorisations and cut-backs per benchmark iteration (one step each), the
  // state's size and how far the trajectory got.
  void report(benchmark::State& state) const {
    state.counters["newton_per_step"] = benchmark::Counter(newtonIterations_, benchmark::Counter::kAvgIterations);
    state.counters["factorisations_per_step"] = benchmark::Counter(factorizations_, benchmark::Counter::kAvgIterations);
    state.counters["cutbacks_per_step"] = benchmark::Counter(cutbacks_, benchmark::Counter::kAvgIterations);
    state.counters["dofs"] = static_cast<double>(z_.size());
    state.counters["t_reached"] = t_;
  }

  Integrator& integrator() { return integrator_; }
  const Eigen::VectorXd& state() const { return z_; }
  // after a step: the state it started from
  const Eigen::VectorXd& previousState() const { return zNext_; }
  double time() const { return t_; }
  double dt() const { return dt_; }
  long newtonIterations() const { return newtonIterations_; }
  const std::string& failure() const { return failure_; }

 private:
  double dt_;
  Integrator integrator_;
  Eigen::VectorXd z_, zNext_;
  double t_;
  long newtonIterations_ = 0, factorizations_ = 0, cutbacks_ = 0;
  std::string failure_;
};

// Time per step of `scheme` at the scene's dt from the initial state, stepping on from the
// previous state so every iteration is a step of one trajectory.
void stepBenchmark(benchmark::State& state, const std::shared_ptr<const CompiledScene>& scene, Scheme scheme) {
  Trajectory trajectory(*scene, scheme, scene->model->initialState(), 0.0, scene->settings.dt);
  for (auto _ : state)
    if (!trajectory.step()) {
      state.SkipWithError(trajectory.failure().c_str());
      break;
    }
  trajectory.report(state);
}

// A scheme as the command line names it: the EEM cases of the thermal scenes fix the thermal
// variable; plain EEM (for the rigid scenes, which have no thermal dofs) and the standard
// rules run in the one the scene declares.
struct SchemeChoice {
  const char* name;
  Scheme scheme;
  std::optional<ThermalVariable> variable;
};

const SchemeChoice kEem{"eem", Scheme::Eem, std::nullopt};
const SchemeChoice kEemEntropy{"eem-entropy", Scheme::Eem, ThermalVariable::Entropy};
const SchemeChoice kEemTemperature{"eem-temperature", Scheme::Eem, ThermalVariable::Temperature};
const SchemeChoice kMidpoint{"midpoint", Scheme::Midpoint, std::nullopt};
const SchemeChoice kTrapezoidal{"trapezoidal", Scheme::Trapezoidal, std::nullopt};
const SchemeChoice kEem4Entropy{"eem4-entropy", Scheme::Eem4, ThermalVariable::Entropy};
const SchemeChoice kEem4Temperature{"eem4-temperature", Scheme::Eem4, ThermalVariable::Temperature};

// Compile the scene once per case (outside any timing) and register its step benchmark.
void registerCases(const std::string& sceneName, const SceneSource& source,
                   std::initializer_list<SchemeChoice> choices) {
  for (const SchemeChoice& choice : choices) {
    auto scene = std::make_shared<const CompiledScene>(source(choice.variable));
    benchmark::RegisterBenchmark((sceneName + "/" + choice.name).c_str(), stepBenchmark, scene, choice.scheme)
        ->Unit(benchmark::kMicrosecond);
  }
}

// Wall-clock seconds f() takes.
template <class F>
double secondsOf(const F& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// A solid scene in its loaded phase, prepared on the case's first run (outside timing) and
// kept for its later runs and repetitions: the state at `loadedTime`, reached from rest by
// EEM steps of `loadingDt` (in the load larger than the scene's dt, so that the finest mesh
// gets there in a few steps), the trajectory whose integrator took them (its sparse LU analysed, so no
// timed step pays for that) and a second solver of the same pattern for timing the solve alone.
struct LoadedSolid {
  std::shared_ptr<const CompiledScene> scene;
  double loadedTime, loadingDt;
  bool loaded = false;
  std::optional<Trajectory> trajectory;
  Eigen::VectorXd state;
  std::unique_ptr<CondensedSolver> solver;

  // "" or what failed
  std::string load() {
    const Model& model = *scene->model;
    trajectory.emplace(*scene, Scheme::Eem, model.initialState(), 0.0, loadingDt);
    if (!trajectory->stepTo(loadedTime)) return trajectory->failure();
    state = trajectory->state();
    const Assembler& system = trajectory->integrator().evaluate(state, state, loadedTime, scene->settings.dt);
    solver = std::make_unique<CondensedSolver>(model.layout(), system.tangent());
    if (!solver->factorize(system.tangent(), true)) return "singular tangent at the loaded state";
    loaded = true;
    return "";
  }
};

// Time per EEM step of a solid at the scene's dt from its loaded state (every run starts
// there), and the parts of a Newton iteration, timed after each step (timing paused) on the
// step just taken: assembly (Integrator::evaluate: every component's residual and tangent
// scattered into the fixed pattern) at the end state, as in a Newton iteration, and at the
// start state, as in the step's first evaluation (zNew = zOld, where the discrete stress is
// the cheaper midpoint stress), and the linear solve (CondensedSolver::factorize + solve with
// the pattern analysed, as in every Newton iteration after a run's first). Counters:
// assembly_ms per iteration's evaluation, assembly_start_ms for the first, solve_ms per
// factorise + solve, condensed unknowns, and the shares of the step they make: a step
// evaluates once at its start and once per Newton iteration (when the line search takes full
// steps and there is no cut-back, as in these runs: cutbacks_per_step = 0) and factorises
// and solves once per iteration.
void loadedSolidBenchmark(benchmark::State& state, const std::shared_ptr<LoadedSolid>& solid) {
  if (!solid->loaded) {
    const std::string failure = solid->load();
    if (!failure.empty()) {
      state.SkipWithError(("loading failed: " + failure).c_str());
      return;
    }
  }
  Trajectory& trajectory = *solid->trajectory;
  trajectory.restart(solid->state, solid->loadedTime, solid->scene->settings.dt);
  Integrator& integrator = trajectory.integrator();
  CondensedSolver& solver = *solid->solver;
  const double dt = trajectory.dt();
  Eigen::VectorXd increment(solid->state.size());

  // the parts are those of a full Newton iteration (evaluate, factorise, solve); simplified
  // Newton's iterations mostly evaluate the residual alone and solve with a kept factorisation
  const bool timeParts = solid->scene->settings.newton.reuseContraction == 0.0;
  double stepSeconds = 0.0, startSeconds = 0.0, assemblySeconds = 0.0, solveSeconds = 0.0;
  for (auto _ : state) {
    bool stepped = false;
    stepSeconds += secondsOf([&] { stepped = trajectory.step(); });
    if (!stepped) {
      state.SkipWithError(trajectory.failure().c_str());
      break;
    }
    if (!timeParts) continue;
    state.PauseTiming();
    const double t = trajectory.time() - dt;
    startSeconds +=
        secondsOf([&] { integrator.evaluate(trajectory.previousState(), trajectory.previousState(), t, dt); });
    const Assembler* system = nullptr;
    assemblySeconds +=
        secondsOf([&] { system = &integrator.evaluate(trajectory.previousState(), trajectory.state(), t, dt); });
    solveSeconds += secondsOf([&] {
      solver.factorize(system->tangent(), false);
      solver.solve(system->residual(), increment);
    });
    state.ResumeTiming();
  }
  trajectory.report(state);
  if (!timeParts) return;
  const double newtonPerStep = static_cast<double>(trajectory.newtonIterations()) / state.iterations();
  state.counters["condensed"] = solver.condensedSize();
  state.counters["assembly_ms"] = benchmark::Counter(1e3 * assemblySeconds, benchmark::Counter::kAvgIterations);
  state.counters["assembly_start_ms"] = benchmark::Counter(1e3 * startSeconds, benchmark::Counter::kAvgIterations);
  state.counters["solve_ms"] = benchmark::Counter(1e3 * solveSeconds, benchmark::Counter::kAvgIterations);
  state.counters["assembly_share"] = (startSeconds + newtonPerStep * assemblySeconds) / stepSeconds;
  state.counters["solve_share"] = newtonPerStep * solveSeconds / stepSeconds;
}

// Where the timed steps of an L-block case start: in the load (t = 1, a fifth into it, reached
// by two steps of 0.5), or in free flight (t = 6, a time unit after the load, reached by the
// scene's own steps of 0.1: longer steps would leave out the unresolved motion that sets the
// iterations there).
enum class LBlockPhase { Loading, FreeFlight };

// Register the EEM step (dt 0.1) of the L-block at mesh level `level`, `steps` timed steps
// per run from the phase's start; "eem" with full Newton, "eem-simplified" with simplified
// Newton, "-symmetric" with the symmetric part factorised, "-free" in free flight.
void registerLBlock(const std::string& name, int level, LBlockVariant variant, int steps,
                    LBlockNewton newton = LBlockNewton::Full, LBlockPhase phase = LBlockPhase::Loading) {
  auto solid = std::make_shared<LoadedSolid>();
  solid->scene = std::make_shared<const CompiledScene>(compileScene(lblock(level, variant, 0.1, newton)));
  const bool free = phase == LBlockPhase::FreeFlight;
  solid->loadedTime = free ? 6.0 : 1.0;
  solid->loadingDt = free ? 0.1 : 0.5;
  const std::string scheme = newton == LBlockNewton::Full         ? "/eem"
                             : newton == LBlockNewton::Simplified ? "/eem-simplified"
                                                                  : "/eem-simplified-symmetric";
  benchmark::RegisterBenchmark((name + "/level" + std::to_string(level) + scheme + (free ? "-free" : "")).c_str(),
                               loadedSolidBenchmark, solid)
      ->Iterations(steps)
      ->Unit(benchmark::kMillisecond);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;

  // every case is registered; --benchmark_filter picks which run
  registerCases("two_thermo_springs", sceneFile("two_thermo_springs.xml"),
                {kEemEntropy, kEemTemperature, kMidpoint, kTrapezoidal, kEem4Entropy, kEem4Temperature});
  registerCases("thermo_visco_elastic", sceneFile("thermo_visco_elastic.xml"),
                {kEemEntropy, kEemTemperature, kMidpoint, kTrapezoidal, kEem4Entropy, kEem4Temperature});
  registerCases("thermo_spring_chain_1000", sceneSpec(thermoSpringChain(1000, 0.05)),
                {kEemEntropy, kEemTemperature, kMidpoint, kEem4Entropy});
  // rigid multibody: a long open chain under both enforcements, and a spatial closed loop
  registerCases("rigid_chain_50", sceneSpec(rigidChain(50, Enforcement::AugmentedLagrangian, 1e4, 1e-3)), {kEem});
  registerCases("rigid_chain_50_penalty", sceneSpec(rigidChain(50, Enforcement::Penalty, 1e8, 1e-3)), {kEem});
  registerCases("slider_crank_spatial", sceneFile("slider_crank_spatial.xml"), {kEem, kMidpoint});
  // finite-element solids: the tumbling L-block by mesh level (90 to 14 400 nodes)
  registerLBlock("lblock_elastic", 1, LBlockVariant::Elastic, 20);
  registerLBlock("lblock_elastic", 2, LBlockVariant::Elastic, 20);
  registerLBlock("lblock_elastic", 4, LBlockVariant::Elastic, 10);
  registerLBlock("lblock_elastic", 7, LBlockVariant::Elastic, 2);  // one to two minutes: seconds per Newton iteration
  // as scenes/lblock_elastic.xml and lblock_viscoelastic.xml run them: simplified Newton
  for (int level : {1, 4})
    registerLBlock("lblock_elastic", level, LBlockVariant::Elastic, 10, LBlockNewton::Simplified);
  registerLBlock("lblock_elastic", 1, LBlockVariant::Elastic, 50, LBlockNewton::Simplified, LBlockPhase::FreeFlight);
  registerLBlock("lblock_elastic", 4, LBlockVariant::Elastic, 10, LBlockNewton::SimplifiedSymmetric);
  registerLBlock("lblock_viscoelastic", 1, LBlockVariant::Viscoelastic, 20, LBlockNewton::Simplified);
  registerLBlock("lblock_viscoelastic", 1, LBlockVariant::Viscoelastic, 20);
  registerLBlock("lblock_viscoelastic", 2, LBlockVariant::Viscoelastic, 10);
  registerLBlock("lblock_thermoelastic", 1, LBlockVariant::Thermoelastic, 20);
  registerLBlock("lblock_thermoelastic", 2, LBlockVariant::Thermoelastic, 20);
  registerLBlock("lblock_thermoelastic", 4, LBlockVariant::Thermoelastic, 10);

  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
