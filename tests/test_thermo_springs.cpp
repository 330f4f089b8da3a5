// Two thermo-spring system (docs/theory.md section 11.1, after [Conde Martín 2016] section 2.1)
// over 10^4 steps at a step where the implicit midpoint rule visibly drifts: EEM keeps energy and
// angular momentum and never lets entropy decrease, with either thermal variable.
#include "support.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace mpx::test {
namespace {

constexpr double kStep = 0.2;      // the scene's step: about 1/30 of the fast period
constexpr double kEndTime = 2000;  // 10^4 steps

double maxRelativeDrift(const std::vector<double>& series) {
  double drift = 0.0;
  for (double value : series) drift = std::max(drift, std::abs(value - series.front()) / std::abs(series.front()));
  return drift;
}

double maxRelativeDrift(const std::vector<Vec3>& series) {
  double drift = 0.0;
  for (const Vec3& value : series) drift = std::max(drift, (value - series.front()).norm() / series.front().norm());
  return drift;
}

History runTwoSprings(Scheme scheme, ThermalVariable variable, double dt = kStep, double tEnd = kEndTime) {
  const CompiledScene scene = loadScene(scenePath("two_thermo_springs.xml"), variable);
  return run(*scene.model, scheme, dt, tEnd);
}

class TwoThermoSpringsEem : public ::testing::TestWithParam<ThermalVariable> {};

// energy to 1e-10, angular momentum about the fixed point to 1e-10, entropy never decreasing
TEST_P(TwoThermoSpringsEem, ConservesEnergyAndAngularMomentumAndProducesEntropy) {
  const History h = runTwoSprings(Scheme::Eem, GetParam());
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  ASSERT_EQ(h.summary.steps, 10000);
  EXPECT_LE(maxRelativeDrift(h.energy), 1e-10);
  EXPECT_LE(maxRelativeDrift(h.angularMomentum), 1e-10);
  for (std::size_t n = 1; n < h.entropy.size(); ++n)
    ASSERT_GE(h.entropy[n] - h.entropy[n - 1], -1e-14 * std::abs(h.entropy[n])) << "step " << n;
  // heat flows from the hot to the cold spring: entropy must actually grow
  EXPECT_GT(h.entropy.back() - h.entropy.front(), 1e-3);
}

INSTANTIATE_TEST_SUITE_P(BothThermalVariables, TwoThermoSpringsEem,
                         ::testing::Values(ThermalVariable::Entropy, ThermalVariable::Temperature));

// the standard method on the same model: its energy error is reported and orders of magnitude larger
TEST(TwoThermoSprings, MidpointDriftsOrdersOfMagnitudeMoreThanEem) {
  const History eem = runTwoSprings(Scheme::Eem, ThermalVariable::Entropy);
  const History midpoint = runTwoSprings(Scheme::Midpoint, ThermalVariable::Entropy);
  ASSERT_FALSE(midpoint.summary.failed) << midpoint.summary.failure;
  const double eemDrift = maxRelativeDrift(eem.energy), midpointDrift = maxRelativeDrift(midpoint.energy);
  RecordProperty("eem_energy_drift", std::to_string(eemDrift));
  RecordProperty("midpoint_energy_drift", std::to_string(midpointDrift));
  std::printf("max relative energy error over 10^4 steps at dt = %g: EEM %.3e, midpoint %.3e\n", kStep, eemDrift,
              midpointDrift);
  EXPECT_GT(midpointDrift, 1e-4);
  EXPECT_GT(midpointDrift, 1e6 * eemDrift);
}

// without external loads the linear momentum is not conserved (the fixed point pulls), but
// the system's momenta are what the history reports: check they are the masses' sums
TEST(TwoThermoSprings, ReportsMomentaOfTheMasses) {
  const CompiledScene scene = loadScene(scenePath("two_thermo_springs.xml"));
  Measures m;
  scene.model->measure(scene.model->initialState(), m);
  EXPECT_NEAR(m.momentum.x(), 1.0, 1e-15);
  EXPECT_NEAR(m.momentum.y(), 2.0, 1e-15);
  // J = q1 x p1 + q2 x p2 = (1,0,0) x (0,2,0) + (2.2,0,0) x (1,0,0) = (0, 0, 2)
  EXPECT_NEAR(m.angularMomentum.z(), 2.0, 1e-15);
}

// the two EEM variants discretise the same physics differently: their difference at a fixed
// time is O(dt^2), so halving the step divides it by about four
TEST(TwoThermoSprings, EntropyAndTemperatureEemAgreeToSecondOrder) {
  auto difference = [](double dt) {
    const History s = runTwoSprings(Scheme::Eem, ThermalVariable::Entropy, dt, 2.0);
    const History t = runTwoSprings(Scheme::Eem, ThermalVariable::Temperature, dt, 2.0);
    // compare the mechanical state (the thermal blocks hold different variables)
    const int mechanical = 12;
    return (s.states.back().head(mechanical) - t.states.back().head(mechanical)).lpNorm<Eigen::Infinity>();
  };
  const double coarse = difference(0.02), fine = difference(0.01);
  std::printf("EEM entropy vs temperature at t = 2: %.3e (dt 0.02), %.3e (dt 0.01)\n", coarse, fine);
  EXPECT_LT(coarse, 1e-3);
  EXPECT_NEAR(std::log2(coarse / fine), 2.0, 0.2);
}

}  // namespace
}  // namespace mpx::test
