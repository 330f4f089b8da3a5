// eem4 on thermal solids (docs/theory.md section 13.9): the tumbling thermo-viscoelastic cell
// (fourth order in positions and temperatures; E, L and J exact and S never decreasing at a
// large step, the viscous heat kept inside), the thermoelastic L-block (isolated balances after
// the load) and the L-block with Dirichlet faces (energy and entropy balances with boundary heat
// at every step). The step tangents are checked against central differences in
// test_thermal_solids (ThermalCellTangent, eem4 cases).
#include "support.hpp"
#include "thermal_solid_checks.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
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
  // from dt omega = 1 for the fastest elastic mode (about 40 rad/s) down
  const double tEnd = 0.5, finest = 0.003125;
  const VectorXd reference = run(*scene.model, Scheme::Eem4, finest / 4, tEnd).states.back();
  std::vector<double> steps, errors;
  for (double dt = 8 * finest; dt >= finest * (1 - 1e-9); dt /= 2) {
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

TEST(Eem4ThermalSolid, ThermoelasticLBlockKeepsEnergyMomentaAndEntropyAfterTheLoad) {
  const CompiledScene scene = loadScene(scenePath("lblock_thermoelastic.xml"));
  const History h = run(*scene.model, Scheme::Eem4, 0.2, 15.0);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  expectIsolatedBalances(h, "thermoelastic L-block, eem4 dt 0.2");
  expectStepBalances(h, "thermoelastic L-block, eem4 dt 0.2");
}

TEST(Eem4ThermalSolid, DirichletLBlockKeepsBothBalancesWithBoundaryHeatAtEveryStep) {
  const CompiledScene scene = loadScene(scenePath("lblock_thermal_dirichlet.xml"));
  const History h = run(*scene.model, Scheme::Eem4, 0.1, 4.0);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  expectStepBalances(h, "Dirichlet L-block, eem4 dt 0.1");
  EXPECT_GT(std::abs(h.boundaryHeat.back()), 1.0);  // the held faces do exchange heat
}

}  // namespace
}  // namespace mpx::test
