// eem4 on thermal solids (docs/theory.md section 13.9): the tumbling thermo-viscoelastic cell
// (fourth order in positions and temperatures; E, L and J exact and S never decreasing at a
// large step, the viscous heat kept inside; without conduction and branch, S exactly
// constant), the thermoelastic L-block (isolated balances after
// the load) and a face held at a moving temperature (every step ends on it). The L-block with
// Dirichlet faces is checked with eem4 in test_thermal_solids (DirichletLBlock). The step tangents are checked against
// central differences in test_thermal_solids (ThermalCellTangent, eem4 cases).
#include "support.hpp"
#include "thermal_solid_checks.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace mpx::test {
namespace {

using Eigen::VectorXd;

// One box of two hexahedra, spinning and drifting, with a hot face: the expansion sets it
// vibrating, conduction evens the temperatures, the branch (viscosity falling with temperature)
// heats it.
const char* const kTumblingCell = R"(<metriplex name="tumbling_thermal_cell"><simulation dt="0.1" t_end="2"/>
  <solid name="cell" mesh="box" cells="2 1 1" young="1000" poisson="0.3" density="10" velocity="0.1 -0.2 0.3"
         angular_velocity="0.5 0.2 -0.4" heat_capacity="100" conductivity="40" expansion="1e-3"
         reference_temperature="300" temperature="310" branch_lambda="200" branch_mu="50" viscosity="100"
         viscosity_activation="0.02"/>
  <initial_temperature solid="cell" surface="x0" temperature="330"/></metriplex>)";

// Positions over the box size (1) and temperatures over theta_R, at the run's end.
double scaledDifference(const CompiledScene& scene, const VectorXd& a, const VectorXd& b) {
  const SolidPlacement& cell = scene.solids.front();
  const Layout& layout = scene.model->layout();
  const int first = layout.offset(Block::Position), count = layout.size(Block::Position);
  double worst = (a.segment(first, count) - b.segment(first, count)).cwiseAbs().maxCoeff();
  for (std::size_t n = 0; n < cell.thermalDofs.size(); ++n)
    worst = std::max(worst, std::abs(cell.nodeTemperature(a.data(), static_cast<int>(n)) -
                                     cell.nodeTemperature(b.data(), static_cast<int>(n))) /
                                300.0);
  return worst;
}

TEST(Eem4ThermalSolid, TumblingCellConvergesAtOrderFour) {
  const CompiledScene scene = loadSceneText(kTumblingCell, "tumbling_thermal_cell.xml");
  // from dt omega = 0.5 for the fastest elastic mode (about 40 rad/s) down
  const double tEnd = 0.5, finest = 0.003125;
  const VectorXd reference = run(*scene.model, Scheme::Eem4, finest / 4, tEnd).states.back();
  std::vector<double> steps, errors;
  for (double dt = 4 * finest; dt >= finest * (1 - 1e-9); dt /= 2) {
    steps.push_back(dt);
    errors.push_back(scaledDifference(scene, run(*scene.model, Scheme::Eem4, dt, tEnd).states.back(), reference));
    std::printf("tumbling thermal cell, eem4 dt %.5f: error %.3e\n", dt, errors.back());
  }
  EXPECT_NEAR(logLogSlope(steps, errors), 4.0, 0.2);
}

// in both thermal variables (theta, or the capacity's entropy)
TEST(Eem4ThermalSolid, TumblingCellKeepsItsBalancesAtALargeStep) {
  for (ThermalVariable variable : {ThermalVariable::Temperature, ThermalVariable::Entropy}) {
    const CompiledScene scene = loadSceneText(kTumblingCell, "tumbling_thermal_cell.xml", variable);
    const History h = run(*scene.model, Scheme::Eem4, 0.2, 4.0);
    ASSERT_FALSE(h.summary.failed) << h.summary.failure;
    expectIsolatedBalances(h,
                           variable == ThermalVariable::Entropy ? "tumbling cell, entropy form, eem4 dt 0.2"
                                                                : "tumbling cell, eem4 dt 0.2",
                           0.0, 1.0);
    EXPECT_EQ(h.dissipated.back(), 0.0);  // the viscous dissipation stays in the cell as heat
  }
}

// Without conduction and branch the thermoelastic box is adiabatic and reversible: its entropy
// stays put exactly at every step (the stage temperatures weight the heat rows consistently),
// in both thermal variables, while the coupling exchanges energy between heat and strain.
TEST(Eem4ThermalSolid, AdiabaticCellKeepsItsEntropyExactly) {
  std::string scene = kTumblingCell;
  for (const char* removed :
       {R"(branch_lambda="200" branch_mu="50" viscosity="100")", R"(viscosity_activation="0.02")"})
    scene.erase(scene.find(removed), std::string(removed).size());
  scene.replace(scene.find(R"(conductivity="40")"), 17, R"(conductivity="0")");
  for (ThermalVariable variable : {ThermalVariable::Temperature, ThermalVariable::Entropy}) {
    const CompiledScene compiled = loadSceneText(scene, "adiabatic_cell.xml", variable);
    const History h = run(*compiled.model, Scheme::Eem4, 0.1, 2.0);
    ASSERT_FALSE(h.summary.failed) << h.summary.failure;
    const SolidPlacement& cell = compiled.solids.front();
    double worst = 0.0, energyDrift = 0.0, temperatureChange = 0.0;
    for (std::size_t n = 1; n < h.entropy.size(); ++n) {
      worst = std::max(worst, std::abs(h.entropy[n] - h.entropy[n - 1]));
      energyDrift = std::max(energyDrift, std::abs(h.energy[n] - h.energy[0]));
      for (int a = 0; a < static_cast<int>(cell.thermalDofs.size()); ++a)
        temperatureChange = std::max(temperatureChange, std::abs(cell.nodeTemperature(h.states[n].data(), a) -
                                                                 cell.nodeTemperature(h.states[0].data(), a)));
    }
    std::printf(
        "adiabatic cell (%s): largest entropy change per step %.2e of %.3e, nodes' temperatures moved by up "
        "to %.3e K\n",
        variable == ThermalVariable::Entropy ? "entropy form" : "temperature form", worst, std::abs(h.entropy.front()),
        temperatureChange);
    EXPECT_LT(worst, 1e-12 * std::abs(h.entropy.front()));
    EXPECT_LT(energyDrift, 1e-10 * std::abs(h.energy.front()));
    // the coupling does exchange heat and strain: a box whose temperatures stood still would keep
    // its entropy trivially
    EXPECT_GT(temperatureChange, 0.1);
  }
}

TEST(Eem4ThermalSolid, ThermoelasticLBlockKeepsEnergyMomentaAndEntropyAfterTheLoad) {
  const CompiledScene scene = loadScene(scenePath("lblock_thermoelastic.xml"));
  const History h = run(*scene.model, Scheme::Eem4, 0.2, 15.0);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  expectIsolatedBalances(h, "thermoelastic L-block, eem4 dt 0.2");
  expectStepBalances(h, "thermoelastic L-block, eem4 dt 0.2");
}

// A held face whose temperature follows a table with a kink inside a step: the last stage's
// row imposes the step's change of the profile, so every step ends on the profile (stage rows
// alone would leave the end value an extrapolation off it, and the offset would accumulate),
// while the heat through the face keeps both balances.
TEST(Eem4ThermalSolid, HeldFaceEndsEveryStepOnItsMovingTemperature) {
  const char* const scene = R"(<metriplex name="held_face"><simulation dt="0.1" t_end="1"/>
    <solid name="cell" mesh="box" cells="1 1 1" young="1000" poisson="0.3" density="10" heat_capacity="100"
           conductivity="40" expansion="1e-3" reference_temperature="300" temperature="300"/>
    <prescribed_temperature solid="cell" surface="x0" temperature="300" profile="table" times="0 0.33 1"
           values="1 1.05 1.02"/></metriplex>)";
  const CompiledScene compiled = loadSceneText(scene, "held_face.xml");
  const History h = run(*compiled.model, Scheme::Eem4, 0.1, 1.0);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  const SolidPlacement& cell = compiled.solids.front();
  auto profile = [](double t) { return t < 0.33 ? 1.0 + 0.05 * t / 0.33 : 1.05 - 0.03 * (t - 0.33) / 0.67; };
  double worst = 0.0;
  int held = 0;
  for (std::size_t node = 0; node < cell.mesh->nodes.size(); ++node) {
    if (cell.mesh->nodes[node].x() != 0.0) continue;
    ++held;
    for (std::size_t n = 0; n < h.states.size(); ++n)
      worst = std::max(worst, std::abs(cell.nodeTemperature(h.states[n].data(), static_cast<int>(node)) -
                                       300.0 * profile(h.time[n])));
  }
  std::printf("held face: %d nodes, largest departure from the profile at step ends %.2e K\n", held, worst);
  EXPECT_EQ(held, 4);
  EXPECT_LT(worst, 1e-9);
  expectStepBalances(h, "held face, eem4 dt 0.1");
}

}  // namespace
}  // namespace mpx::test
