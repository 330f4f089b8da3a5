// Dissipative systems under EEM: the energy balance closes exactly (the dissipated energy, the
// external work and the boundary heat are accounted for), entropy never decreases in an
// isolated system, and momenta are kept where the model is invariant.
#include "support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace mpx::test {
namespace {

History runScene(const std::string& file, Scheme scheme, std::optional<ThermalVariable> variable = std::nullopt) {
  const CompiledScene scene = loadScene(scenePath(file), variable);
  History h = run(*scene.model, scheme, scene.settings.dt, scene.settings.tEnd);
  EXPECT_FALSE(h.summary.failed) << h.summary.failure;
  return h;
}

double maxDrift(const std::vector<Vec3>& series) {
  double drift = 0.0;
  for (const Vec3& v : series) drift = std::max(drift, (v - series.front()).norm() / series.front().norm());
  return drift;
}

class ThermoViscoElastic : public ::testing::TestWithParam<ThermalVariable> {};

// isolated: E exact, S non-decreasing and growing, linear and angular momentum exact
TEST_P(ThermoViscoElastic, EemConservesEnergyAndMomentaAndProducesEntropy) {
  const History h = runScene("thermo_visco_elastic.xml", Scheme::Eem, GetParam());
  EXPECT_LE(relativeBalanceDrift(h), 1e-12);
  EXPECT_EQ(h.dissipated.back(), 0.0);  // the viscous power heats the element instead
  for (std::size_t n = 1; n < h.entropy.size(); ++n)
    ASSERT_GE(h.entropy[n] - h.entropy[n - 1], -1e-14 * std::abs(h.entropy[n])) << "step " << n;
  EXPECT_GT(h.entropy.back() - h.entropy.front(), 1e-3);
  EXPECT_LE(maxDrift(h.momentum), 1e-12);
  EXPECT_LE(maxDrift(h.angularMomentum), 1e-12);
}

INSTANTIATE_TEST_SUITE_P(BothThermalVariables, ThermoViscoElastic,
                         ::testing::Values(ThermalVariable::Entropy, ThermalVariable::Temperature));

// the same element without a thermal node: E + dissipated exact, E decreasing, momenta exact
TEST(IsothermalMaxwell, EemConservesEnergyPlusDissipated) {
  const History h = runScene("isothermal_maxwell.xml", Scheme::Eem);
  EXPECT_LE(relativeBalanceDrift(h), 1e-10);
  for (std::size_t n = 1; n < h.energy.size(); ++n) {
    ASSERT_LE(h.energy[n], h.energy[n - 1] + 1e-14 * std::abs(h.energy[0])) << "step " << n;
    ASSERT_GE(h.dissipated[n], h.dissipated[n - 1]) << "step " << n;
  }
  EXPECT_GT(h.dissipated.back(), 1e-2 * h.energy.front());
  EXPECT_LE(maxDrift(h.momentum), 1e-12);
  EXPECT_LE(maxDrift(h.angularMomentum), 1e-12);
}

// the midpoint rule on the same model leaves a visible gap in the balance
TEST(IsothermalMaxwell, MidpointBalanceErrorIsLarger) {
  const double eem = relativeBalanceDrift(runScene("isothermal_maxwell.xml", Scheme::Eem));
  const double midpoint = relativeBalanceDrift(runScene("isothermal_maxwell.xml", Scheme::Midpoint));
  std::printf("isothermal Maxwell, energy balance error: EEM %.3e, midpoint %.3e\n", eem, midpoint);
  EXPECT_GT(midpoint, 1e4 * eem);
}

// gravity (in E), a ramped force (external work) and a dashpot (dissipated) together
TEST(KelvinVoigtPendulum, EemClosesTheBalanceWithExternalWork) {
  const History h = runScene("damped_pendulum_spring.xml", Scheme::Eem);
  EXPECT_LE(relativeBalanceDrift(h), 1e-11);
  EXPECT_GT(std::abs(h.externalWork.back()), 1.0);
  EXPECT_GT(h.dissipated.back(), 1.0);
}

// The summary's drift is the whole run's largest |E + D - W - Q - E_0| over the whole run's
// largest energy, also for a mass starting from rest, where the first step's energy is ~dt^4:
// a ratio taken step by step would be set by that tiny first step and grow as dt shrinks.
TEST(RunSummary, ReportsTheDriftAgainstTheLargestEnergyOfTheRun) {
  const CompiledScene scene = loadSceneText(R"(<metriplex name="pulled_mass"><simulation dt="0.05" t_end="4"/>
      <anchor name="wall" position="0 0 0"/>
      <mass name="bob" mass="2" position="1 0 0"/>
      <spring name="s" a="wall" b="bob" stiffness="50" rest_length="1"/>
      <damper name="d" a="wall" b="bob" coefficient="0.5"/>
      <force name="pull" on="bob" force="3 4 0" profile="ramp" end="1"/></metriplex>)",
                                            scenePath("pulled_mass.xml"));
  std::vector<double> drifts;
  for (double dt : {0.05, 0.0125}) {
    const History h = run(*scene.model, Scheme::Midpoint, dt, 4.0);
    double largestError = 0.0, largestEnergy = std::abs(h.energy.front());
    for (std::size_t n = 0; n < h.energy.size(); ++n) {
      largestError = std::max(largestError, std::abs(h.energy[n] + h.dissipated[n] - h.externalWork[n] -
                                                     h.boundaryHeat[n] - h.energy.front()));
      largestEnergy = std::max({largestEnergy, std::abs(h.energy[n]), std::abs(h.dissipated[n]),
                                std::abs(h.externalWork[n]), std::abs(h.boundaryHeat[n])});
    }
    EXPECT_EQ(h.summary.maxAbsoluteEnergyBalanceError, largestError) << dt;
    EXPECT_NEAR(h.summary.maxEnergyBalanceError, largestError / largestEnergy, 1e-14 * largestError / largestEnergy)
        << dt;
    drifts.push_back(h.summary.maxEnergyBalanceError);
  }
  std::printf("midpoint drift relative to the run's largest energy: %.3e (dt 0.05), %.3e (dt 0.0125)\n", drifts[0],
              drifts[1]);
  EXPECT_LT(drifts[1], drifts[0]);  // midpoint's balance error falls with the step
}

// heat through a prescribed wall temperature is the only energy exchange
TEST(DirichletHeatedSpring, EemClosesTheBalanceWithBoundaryHeat) {
  const History h = runScene("heated_thermo_spring.xml", Scheme::Eem);
  EXPECT_LE(relativeBalanceDrift(h), 1e-11);
  // the wall is hotter than the spring: heat flows in
  EXPECT_GT(h.boundaryHeat.back(), 0.1);
}

}  // namespace
}  // namespace mpx::test
