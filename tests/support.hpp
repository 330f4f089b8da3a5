#pragma once
// Shared helpers for the tests: fixture scenes from tests/data/, runs collected in memory, and
// conservation checks computed from a run's history.
#include "engine/stepping/method.hpp"
#include "engine/stepping/simulation.hpp"
#include "models/scene/scene_loader.hpp"

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace mpx::test {

// Path of a test fixture in tests/data/ (copies of scenes, so that the demo scenes in scenes/
// may change without changing what the tests assert).
inline std::string scenePath(const std::string& file) { return std::string(METRIPLEX_TEST_DATA_DIR) + "/" + file; }

// The whole text of a file ("" if it cannot be read).
inline std::string readFile(const std::string& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

// Test-name fragment of a one-step scheme.
inline std::string schemeName(Scheme scheme) {
  switch (scheme) {
    case Scheme::Eem:
      return "eem";
    case Scheme::Eem4:
      return "eem4";
    case Scheme::Midpoint:
      return "midpoint";
    case Scheme::Trapezoidal:
      return "trapezoidal";
  }
  return "unknown";
}

// The smallest scene with load breakpoints: a mass on a spring (k = 40, rest length 1) from a
// wall, pushed by `force` along a load profile, e.g. {{"profile", "hat"}, {"period", 0.7}}.
inline CompiledScene pushedSpring(double dt, double tEnd, const Vec3& force, std::initializer_list<Attribute> profile) {
  SceneSpec spec;
  spec.settings.dt = dt;
  spec.settings.tEnd = tEnd;
  spec.add("anchor", {{"name", "wall"}, {"position", Vec3(0, 0, 0)}});
  spec.add("mass", {{"name", "m"}, {"mass", 1.0}, {"position", Vec3(1, 0, 0)}});
  spec.add("spring", {{"name", "s"}, {"a", "wall"}, {"b", "m"}, {"stiffness", 40.0}, {"rest_length", 1.0}});
  ElementSpec& push = spec.add("force", {{"name", "push"}, {"on", "m"}, {"force", force}});
  for (const Attribute& attribute : profile) push.set(attribute.name, attribute.value);
  return compileScene(spec);
}

// Everything a run reports, step by step.
struct History {
  std::vector<double> time, dt, energy, entropy, dissipated, externalWork, boundaryHeat, boundaryEntropy;
  std::vector<Vec3> momentum, angularMomentum;
  std::vector<Eigen::VectorXd> states;
  std::vector<int> newtonIterations;  // of each step
  RunSummary summary;
};

// The history of a run made by `runWith(sink)`.
template <class Runner>
History collect(Runner runWith) {
  History h;
  h.summary = runWith([&](const StepRecord& r) {
    h.time.push_back(r.time);
    h.dt.push_back(r.dt);
    h.energy.push_back(r.measures->energy);
    h.entropy.push_back(r.measures->entropy);
    h.dissipated.push_back(r.crossed.dissipated);
    h.externalWork.push_back(r.crossed.externalWork);
    h.boundaryHeat.push_back(r.crossed.boundaryHeat);
    h.boundaryEntropy.push_back(r.crossed.boundaryEntropy);
    h.momentum.push_back(r.measures->momentum);
    h.angularMomentum.push_back(r.measures->angularMomentum);
    h.states.push_back(*r.state);
    h.newtonIterations.push_back(r.newtonIterations);
  });
  return h;
}

inline History run(const Model& model, Scheme scheme, double dt, double tEnd, NewtonSettings newton = {}) {
  return collect([&](const StepSink& sink) { return simulate(model, {scheme, dt, tEnd, newton, {}}, sink); });
}

// SUNDIALS IDA at rtol = atol (per dof scale), history rows every outputStep (default t_end/20).
inline History runIda(const Model& model, double rtol, double tEnd, bool sundialsKlu = false, double outputStep = 0.0) {
  MethodParameters parameters;
  parameters.sundialsKlu = sundialsKlu;
  parameters.dt = outputStep > 0.0 ? outputStep : tEnd / 20;
  parameters.tEnd = tEnd;
  parameters.relativeTolerance = rtol;
  parameters.absoluteTolerance = rtol;
  return collect([&](const StepSink& sink) { return runMethod(model, *methodByName("ida"), parameters, sink); });
}

// Least-squares slope of log(y) against log(x): an observed order of convergence.
inline double logLogSlope(const std::vector<double>& x, const std::vector<double>& y) {
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < x.size(); ++i) mx += std::log(x[i]) / x.size(), my += std::log(y[i]) / x.size();
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxy += (std::log(x[i]) - mx) * (std::log(y[i]) - my);
    sxx += (std::log(x[i]) - mx) * (std::log(x[i]) - mx);
  }
  return sxy / sxx;
}

// Conservation checks computed from a history (not taken from the engine's own summary).

// Largest |B_n - B_0| of the balance B = E + D - W - Q over the run (J).
inline double maxBalanceDrift(const History& h) {
  double drift = 0.0;
  for (std::size_t n = 0; n < h.energy.size(); ++n)
    drift =
        std::max(drift, std::abs(h.energy[n] + h.dissipated[n] - h.externalWork[n] - h.boundaryHeat[n] - h.energy[0]));
  return drift;
}

// What the balance is judged against: the largest |E|, D, |W| or |Q| of the run.
inline double largestEnergy(const History& h) {
  double scale = 0.0;
  for (std::size_t n = 0; n < h.energy.size(); ++n)
    scale = std::max({scale, std::abs(h.energy[n]), std::abs(h.dissipated[n]), std::abs(h.externalWork[n]),
                      std::abs(h.boundaryHeat[n])});
  return scale;
}

// The balance drift relative to the initial energy (for runs that start with energy).
inline double relativeBalanceDrift(const History& h) { return maxBalanceDrift(h) / std::abs(h.energy.front()); }

// Entropy may fall from one step to the next by at most this, relative to |S| (round-off of a
// sum of element entropies).
inline constexpr double kEntropyRoundOff = 1e-14;

// The first step whose entropy falls below its predecessor's by more than kEntropyRoundOff,
// or -1 when it never does.
inline int firstEntropyDecrease(const History& h) {
  for (std::size_t n = 1; n < h.entropy.size(); ++n)
    if (h.entropy[n] - h.entropy[n - 1] < -kEntropyRoundOff * std::abs(h.entropy[n])) return static_cast<int>(n);
  return -1;
}

// Newton gave up, or the balance is off by more than the engine's blow-up threshold.
inline bool blewUp(const History& h) { return h.summary.failed || relativeBalanceDrift(h) > kBlowUpEnergyError; }

// A compiled scene with the run that integrated it (the history refers to the model).
struct SceneRun {
  CompiledScene scene;
  History history;
};

}  // namespace mpx::test
