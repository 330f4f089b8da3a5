#pragma once
// Shared helpers for the tests: scenes from inline XML or scenes/, and runs collected in memory.
#include "engine/stepping/simulation.hpp"
#include "models/scene/scene_loader.hpp"

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace mpx::test {

// Path of a file in scenes/.
inline std::string scenePath(const std::string& file) { return std::string(METRIPLEX_SCENES_DIR) + "/" + file; }

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
    case Scheme::Eem: return "eem";
    case Scheme::Midpoint: return "midpoint";
    case Scheme::Trapezoidal: return "trapezoidal";
  }
  return "unknown";
}

// Everything a run reports, step by step.
struct History {
  std::vector<double> time, energy, entropy, dissipated, externalWork, boundaryHeat;
  std::vector<Vec3> momentum, angularMomentum;
  std::vector<Eigen::VectorXd> states;
  RunSummary summary;
};

inline History run(const Model& model, Scheme scheme, double dt, double tEnd, NewtonSettings newton = {}) {
  History h;
  RunOptions options{scheme, dt, tEnd, newton};
  h.summary = simulate(model, options, [&](const StepRecord& r) {
    h.time.push_back(r.time);
    h.energy.push_back(r.measures->energy);
    h.entropy.push_back(r.measures->entropy);
    h.dissipated.push_back(r.dissipated);
    h.externalWork.push_back(r.externalWork);
    h.boundaryHeat.push_back(r.boundaryHeat);
    h.momentum.push_back(r.measures->momentum);
    h.angularMomentum.push_back(r.measures->angularMomentum);
    h.states.push_back(*r.state);
  });
  return h;
}

// A compiled scene with the run that integrated it (the history refers to the model).
struct SceneRun {
  CompiledScene scene;
  History history;
};

}  // namespace mpx::test
