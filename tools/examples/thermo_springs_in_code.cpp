// Metriplex as a library: build a scene in code, integrate it with EEM and with SUNDIALS IDA,
// and print where the energy and entropy went. Exits 1 if EEM's balance is not exact to
// round-off or its entropy ever decreases, so it doubles as a check of an installed Metriplex.
//
// The system: two masses hang in a chain from a fixed point by two thermo-elastic springs that
// exchange heat (the two thermo-spring benchmark, docs/theory.md). It is isolated, so its
// energy stays constant and its entropy grows while the springs' temperatures equalise.
#include "engine/stepping/method.hpp"
#include "models/scene/scene_loader.hpp"

#include <cmath>
#include <cstdio>
#include <tuple>

int main() {
  using mpx::Vec3;

  // 1. The scene, element by element, with the tags and attributes of the XML format
  //    (docs/scene-format.md); every attribute is validated as if read from a file.
  mpx::SceneSpec scene;
  scene.name = "thermo_springs_in_code";
  scene.settings.dt = 0.2;
  scene.settings.tEnd = 20.0;  // 100 steps
  scene.settings.thermalVariable = mpx::ThermalVariable::Entropy;
  scene.add("anchor", {{"name", "origin"}, {"position", Vec3(0, 0, 0)}});
  scene.add("mass", {{"name", "m1"}, {"mass", 1.0}, {"position", Vec3(1, 0, 0)}, {"velocity", Vec3(0, 2, 0)}});
  scene.add("mass", {{"name", "m2"}, {"mass", 1.0}, {"position", Vec3(2.2, 0, 0)}, {"velocity", Vec3(1, 0, 0)}});
  for (const auto& [name, a, b, entropy] : {std::tuple{"s1", "origin", "m1", 1.0}, std::tuple{"s2", "m1", "m2", 0.2}})
    scene.add("thermo_spring", {{"name", name},
                                {"a", a},
                                {"b", b},
                                {"stiffness", 1.0},
                                {"coupling", 1.0},
                                {"rest_length", 1.0},
                                {"heat_capacity", 1.0},
                                {"reference_temperature", 1.0},
                                {"entropy", entropy}});
  scene.add("heat_link", {{"name", "h12"}, {"a", "s1"}, {"b", "s2"}, {"conductivity", 1.0}});

  // 2. Compile it into a model: one state z holding positions, velocities and the springs'
  //    entropies, and one component per element.
  const mpx::CompiledScene compiled = mpx::compileScene(scene);
  const mpx::Model& model = *compiled.model;

  // 3. Integrate with each method; the sink sees every step's state and its measures.
  bool exact = true;
  for (const char* name : {"eem", "ida"}) {
    mpx::MethodParameters parameters;
    parameters.dt = scene.settings.dt;  // IDA: the output interval; its own steps follow rtol
    parameters.tEnd = scene.settings.tEnd;
    parameters.relativeTolerance = parameters.absoluteTolerance = 1e-8;
    double energy = 0.0, entropy = 0.0;
    const mpx::RunSummary summary =
        mpx::runMethod(model, *mpx::methodByName(name), parameters, [&](const mpx::StepRecord& step) {
          energy = step.measures->energy;
          entropy = step.measures->entropy;
        });

    // 4. The balance: E + dissipated - external work - boundary heat - E0, largest over the
    //    run relative to the run's largest energy; and the least entropy produced in a step.
    std::printf("%-4s %4d steps  E(t_end) = %.15f  S(t_end) = %.6f  energy drift %.2e  min entropy production %.2e\n",
                name, summary.steps, energy, entropy, summary.maxEnergyBalanceError, summary.minEntropyProduction);
    if (std::string(name) == "eem")
      exact = !summary.failed && summary.maxEnergyBalanceError < 1e-12 && summary.minEntropyProduction > -1e-14;
  }
  // EEM keeps E to round-off and S non-decreasing at any step; IDA only to its tolerance
  std::printf("EEM balance %s\n", exact ? "exact to round-off" : "VIOLATED");
  return exact ? 0 : 1;
}
