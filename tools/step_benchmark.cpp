// metriplex_step_benchmark: cost of one integrator step along a real trajectory (time, Newton
// iterations, cut-backs) for the benchmark scenes and generated chains of thermo-springs and of
// rigid links.
// Reproduce and read the figures with docs/performance.md.
#include "models/scene/scene_loader.hpp"

#include <benchmark/benchmark.h>

#include <cmath>
#include <functional>
#include <initializer_list>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
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

// Scenes generated in code are compiled from their XML text; `label` names them in messages.
SceneSource sceneText(std::string xml, std::string label) {
  return [xml = std::move(xml), label = std::move(label)](std::optional<ThermalVariable> variable) {
    return loadSceneText(xml, label, variable);
  };
}

// A chain fixed to an anchor at the origin: masses along x at spacing 1.1 (springs pre-
// stretched by 0.1) with a transverse velocity pattern, a thermo-spring between consecutive
// points, temperatures varying along the chain and heat links between neighbouring springs.
std::string thermoSpringChainXml(int masses, double dt) {
  std::ostringstream xml;
  xml << "<metriplex name=\"thermo_spring_chain\">\n"
      << "  <simulation dt=\"" << dt << "\" t_end=\"100\" thermal_variable=\"entropy\"/>\n"
      << "  <anchor name=\"origin\" position=\"0 0 0\"/>\n";
  const auto point = [](int i) { return i == 0 ? std::string("origin") : "m" + std::to_string(i); };
  for (int i = 1; i <= masses; ++i) {
    xml << "  <mass name=\"" << point(i) << "\" mass=\"1\" position=\"" << 1.1 * i << " 0 0\" velocity=\"0 "
        << 0.2 * std::sin(0.3 * i) << ' ' << 0.1 * std::cos(0.7 * i) << "\"/>\n"
        << "  <thermo_spring name=\"s" << i << "\" a=\"" << point(i - 1) << "\" b=\"" << point(i)
        << "\" stiffness=\"1\" coupling=\"1\" rest_length=\"1\" heat_capacity=\"1\""
        << " reference_temperature=\"1\" temperature=\"" << 1.0 + 0.5 * std::sin(i) << "\"/>\n";
    if (i > 1)
      xml << "  <heat_link name=\"h" << i << "\" a=\"s" << i - 1 << "\" b=\"s" << i << "\" conductivity=\"1\"/>\n";
  }
  xml << "</metriplex>\n";
  return xml.str();
}

// A chain of rigid links hinged to an anchor at the origin, released from rest horizontal in
// gravity: link i (1 kg, a 0.5 x 0.05 x 0.05 m box) is centred at (0.25 + 0.5 i, 0, 0) and
// joined to its predecessor by a revolute joint about y at their common end; `enforcement`
// and `stiffness` become the scene's <constraints> default.
std::string rigidChainXml(int links, const std::string& enforcement, double stiffness, double dt) {
  const double mass = 1.0, length = 0.5, width = 0.05;
  const double axial = mass * (width * width + width * width) / 12;
  const double transverse = mass * (length * length + width * width) / 12;
  std::ostringstream xml;
  xml.precision(17);
  xml << "<metriplex name=\"rigid_chain\">\n"
      << "  <simulation dt=\"" << dt << "\" t_end=\"100\"/>\n"
      << "  <constraints enforcement=\"" << enforcement << "\" stiffness=\"" << stiffness << "\"/>\n"
      << "  <gravity g=\"0 0 -9.81\"/>\n"
      << "  <anchor name=\"origin\" position=\"0 0 0\"/>\n";
  const auto link = [](int i) { return i < 0 ? std::string("origin") : "l" + std::to_string(i); };
  for (int i = 0; i < links; ++i)
    xml << "  <body name=\"" << link(i) << "\" mass=\"" << mass << "\" inertia=\"" << axial << ' ' << transverse
        << ' ' << transverse << "\" position=\"" << length * (i + 0.5) << " 0 0\"/>\n"
        << "  <joint name=\"j" << i << "\" type=\"revolute\" a=\"" << link(i - 1) << "\" b=\"" << link(i)
        << "\" anchor=\"" << length * i << " 0 0\" axis=\"0 1 0\"/>\n";
  xml << "</metriplex>\n";
  return xml.str();
}

// Time per step of `scheme` at the scene's dt, stepping on from the previous state so every
// iteration is a step of one trajectory; the integrator and both states exist before timing.
void stepBenchmark(benchmark::State& state, const std::shared_ptr<const CompiledScene>& scene, Scheme scheme) {
  const Model& model = *scene->model;
  const double dt = scene->settings.dt;
  Integrator integrator(model, scheme, scene->settings.newton);
  Eigen::VectorXd z = model.initialState(), zNext(z.size());
  double t = 0.0;
  long newtonIterations = 0, cutbacks = 0;
  for (auto _ : state) {
    const StepOutcome outcome = integrator.advance(z, t, dt, zNext);
    if (!outcome.converged) {
      state.SkipWithError(("step failed at t = " + std::to_string(t) + ": " + outcome.failure).c_str());
      break;
    }
    newtonIterations += outcome.iterations;
    cutbacks += outcome.cutbacks;
    z.swap(zNext);
    t += dt;
  }
  state.counters["newton_per_step"] = benchmark::Counter(newtonIterations, benchmark::Counter::kAvgIterations);
  state.counters["cutbacks_per_step"] = benchmark::Counter(cutbacks, benchmark::Counter::kAvgIterations);
  state.counters["dofs"] = model.layout().total();
  state.counters["t_reached"] = t;
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

// Compile the scene once per case (outside any timing) and register its step benchmark.
void registerCases(const std::string& sceneName, const SceneSource& source,
                   std::initializer_list<SchemeChoice> choices) {
  for (const SchemeChoice& choice : choices) {
    auto scene = std::make_shared<const CompiledScene>(source(choice.variable));
    benchmark::RegisterBenchmark((sceneName + "/" + choice.name).c_str(), stepBenchmark, scene, choice.scheme)
        ->Unit(benchmark::kMicrosecond);
  }
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;

  // every case is registered; --benchmark_filter picks which run
  registerCases("two_thermo_springs", sceneFile("two_thermo_springs.xml"),
                {kEemEntropy, kEemTemperature, kMidpoint, kTrapezoidal});
  registerCases("thermo_visco_elastic", sceneFile("thermo_visco_elastic.xml"),
                {kEemEntropy, kEemTemperature, kMidpoint, kTrapezoidal});
  registerCases("thermo_spring_chain_1000", sceneText(thermoSpringChainXml(1000, 0.05), "thermo_spring_chain"),
                {kEemEntropy, kEemTemperature, kMidpoint});
  // rigid multibody: a long open chain under both enforcements, and a spatial closed loop
  registerCases("rigid_chain_50", sceneText(rigidChainXml(50, "augmented_lagrangian", 1e4, 1e-3), "rigid_chain"),
                {kEem});
  registerCases("rigid_chain_50_penalty", sceneText(rigidChainXml(50, "penalty", 1e8, 1e-3), "rigid_chain"),
                {kEem});
  registerCases("slider_crank_spatial", sceneFile("slider_crank_spatial.xml"), {kEem, kMidpoint});

  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
