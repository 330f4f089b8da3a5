// The fourth-order EEM step (eem4: energy-consistent two-stage Gauss collocation, docs/theory.md
// section 13): observed order 4 against a fine run, the energy balance and entropy production at
// every step also at large steps, exact momenta, the stability of a stiff linear dissipative
// mode, and the scenes it refuses.
#include "support.hpp"

#include "engine/core/input_error.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace mpx::test {
namespace {

struct OrderCase {
  const char* scene;
  ThermalVariable variable;
};

constexpr double kOrderEndTime = 2.0;
constexpr double kOrderSteps[] = {0.2, 0.1, 0.05, 0.025};
constexpr double kOrderReferenceStep = 0.025 / 16;

Eigen::VectorXd finalState(const Model& model, double dt) {
  const History h = run(model, Scheme::Eem4, dt, kOrderEndTime);
  EXPECT_FALSE(h.summary.failed) << h.summary.failure;
  return h.states.back();
}

class Eem4Order : public ::testing::TestWithParam<OrderCase> {};

// The log-log slope of the final-state error against the step is 4 +- 0.2.
TEST_P(Eem4Order, IsFour) {
  const OrderCase c = GetParam();
  const CompiledScene scene = loadScene(scenePath(c.scene), c.variable);
  const Eigen::VectorXd reference = finalState(*scene.model, kOrderReferenceStep);
  std::vector<double> dts(std::begin(kOrderSteps), std::end(kOrderSteps)), errors;
  for (double dt : dts) errors.push_back((finalState(*scene.model, dt) - reference).lpNorm<Eigen::Infinity>());
  const double order = logLogSlope(dts, errors);
  std::printf("eem4 on %s: errors", c.scene);
  for (double e : errors) std::printf(" %.3e", e);
  std::printf(", order %.3f\n", order);
  EXPECT_NEAR(order, 4.0, 0.2);
}

INSTANTIATE_TEST_SUITE_P(DiscreteSystems, Eem4Order,
                         ::testing::Values(OrderCase{"two_thermo_springs.xml", ThermalVariable::Entropy},
                                           OrderCase{"two_thermo_springs.xml", ThermalVariable::Temperature},
                                           OrderCase{"thermo_visco_elastic.xml", ThermalVariable::Temperature},
                                           OrderCase{"thermo_visco_elastic.xml", ThermalVariable::Entropy},
                                           OrderCase{"isothermal_maxwell.xml", ThermalVariable::Entropy},
                                           OrderCase{"heated_thermo_spring.xml", ThermalVariable::Temperature}));

struct BalanceCase {
  const char* scene;
  double dt;
  double tEnd;
  double balanceTolerance;     // per step, relative to the run's largest energy
  double productionTolerance;  // per step, relative to |S|
};

class Eem4Balances : public ::testing::TestWithParam<BalanceCase> {};

// At steps far beyond the accurate range: the energy balance E + D - W - Q closes at every step
// and the entropy production of every step is non-negative, to what Newton leaves. Where an
// element turns at an almost constant length (the Maxwell elements once their oscillation has
// died out) the stage gradients' correction is a ratio of two small quantities, Newton stops
// nearer its tolerance, and the balance closes to 1e-9 rather than to round-off
// (docs/theory.md section 13.4).
TEST_P(Eem4Balances, HoldAtEveryStep) {
  const BalanceCase c = GetParam();
  const CompiledScene scene = loadScene(scenePath(c.scene));
  const History h = run(*scene.model, Scheme::Eem4, c.dt, c.tEnd);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  const double scale = largestEnergy(h);
  double worstStep = 0.0, leastProduction = INFINITY;
  for (std::size_t n = 1; n < h.energy.size(); ++n) {
    auto balance = [&](std::size_t k) { return h.energy[k] + h.dissipated[k] - h.externalWork[k] - h.boundaryHeat[k]; };
    worstStep = std::max(worstStep, std::abs(balance(n) - balance(n - 1)) / scale);
    const double production = h.entropy[n] - h.entropy[n - 1] - (h.boundaryEntropy[n] - h.boundaryEntropy[n - 1]);
    leastProduction = std::min(leastProduction, production / std::max(1.0, std::abs(h.entropy[n])));
  }
  std::printf("eem4 on %s at dt %g: worst step balance %.2e, least entropy production %.2e\n", c.scene, c.dt, worstStep,
              leastProduction);
  EXPECT_LT(worstStep, c.balanceTolerance);
  EXPECT_GT(leastProduction, -c.productionTolerance);
}

INSTANTIATE_TEST_SUITE_P(LargeSteps, Eem4Balances,
                         ::testing::Values(BalanceCase{"two_thermo_springs.xml", 1.0, 100.0, 1e-14, kEntropyRoundOff},
                                           BalanceCase{"thermo_visco_elastic.xml", 0.5, 100.0, 1e-9, 1e-10},
                                           BalanceCase{"isothermal_maxwell.xml", 0.5, 100.0, 1e-9, kEntropyRoundOff},
                                           BalanceCase{"heated_thermo_spring.xml", 0.5, 50.0, 1e-14, kEntropyRoundOff},
                                           BalanceCase{"stiff_thermo_chain.xml", 0.25, 10.0, 1e-11, kEntropyRoundOff}));

// Free masses joined by a thermo-visco-elastic element: linear and angular momentum stay at
// their initial values (the Gauss sums of a central force vanish pointwise).
TEST(Eem4Momenta, AreExactForAFreeElement) {
  const CompiledScene scene = loadScene(scenePath("thermo_visco_elastic.xml"));
  const History h = run(*scene.model, Scheme::Eem4, 0.5, 50.0);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  double momentumDrift = 0.0, angularDrift = 0.0;
  for (std::size_t n = 0; n < h.momentum.size(); ++n) {
    momentumDrift = std::max(momentumDrift, (h.momentum[n] - h.momentum[0]).norm() / h.momentum[0].norm());
    angularDrift =
        std::max(angularDrift, (h.angularMomentum[n] - h.angularMomentum[0]).norm() / h.angularMomentum[0].norm());
  }
  EXPECT_LT(momentumDrift, 1e-13);
  EXPECT_LT(angularDrift, 1e-12);
}

// A stiff linear dissipative mode: two heat capacities linked by a conductance with
// dt lambda = 2000. The Gauss stability function R(z) = (1 + z/2 + z^2/12) / (1 - z/2 + z^2/12)
// lies in (0, 1) on the whole negative real axis: the temperature difference decays every step,
// never changes sign and never grows (A-stability without negative sub-steps; R(-inf) = 1, so
// the decay is slow, not L-stable). Energy is kept and entropy rises.
TEST(Eem4Stability, StiffHeatExchangeDecaysMonotonically) {
  const CompiledScene scene = loadSceneText(R"(<metriplex>
    <simulation dt="1" t_end="50" integrator="eem4" thermal_variable="temperature"/>
    <reservoir name="hot" heat_capacity="1" reference_temperature="1" temperature="2"/>
    <reservoir name="cold" heat_capacity="1" reference_temperature="1" temperature="1"/>
    <heat_link name="link" a="hot" b="cold" conductivity="1000"/>
  </metriplex>)",
                                            "stiff_exchange");
  const History h = run(*scene.model, Scheme::Eem4, 1.0, 50.0);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  const double z = -2000.0, r = (1 + z / 2 + z * z / 12) / (1 - z / 2 + z * z / 12);
  double previous = 1.0;
  for (std::size_t n = 1; n < h.states.size(); ++n) {
    const double difference = h.states[n][0] - h.states[n][1];
    ASSERT_GT(difference, 0.0) << "step " << n;
    ASSERT_LT(difference, previous) << "step " << n;
    if (n == 1) {
      EXPECT_NEAR(difference / previous, r, 1e-3) << "decay factor of the first step against R(z)";
    }
    previous = difference;
  }
  EXPECT_EQ(firstEntropyDecrease(h), -1);
  EXPECT_LT(maxBalanceDrift(h), 1e-12 * largestEnergy(h));
}

// Elements without a fourth-order form yet (joints, FE solids) are refused up front.
TEST(Eem4Scope, RefusesElementsWithoutAStageForm) {
  const CompiledScene scene = loadScene(scenePath("double_pendulum.xml"));
  try {
    checkMethodSupports(*methodByName("eem4"), *scene.model, "double_pendulum.xml");
    FAIL() << "eem4 accepted a scene with joints";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("has no fourth-order form for element"), std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace mpx::test
