// Observed order of convergence: the log-log slope of the error at a fixed time against a
// fine reference of the same integrator is 2 (+- 0.1) for EEM with either thermal variable,
// the implicit midpoint rule and the trapezoidal rule; fixed steps end on a load's kinks, so
// that eem4 keeps its order 4 across them.
#include "support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace mpx::test {
namespace {

struct Case {
  const char* scene;
  Scheme scheme;
  ThermalVariable variable;
  const char* label;
};

constexpr double kEndTime = 1.0;
constexpr double kSteps[] = {0.08, 0.04, 0.02, 0.01};
constexpr double kReferenceStep = 0.01 / 32;

Eigen::VectorXd finalState(const Model& model, Scheme scheme, double dt) {
  const History h = run(model, scheme, dt, kEndTime);
  EXPECT_FALSE(h.summary.failed) << h.summary.failure;
  return h.states.back();
}

class ConvergenceOrder : public ::testing::TestWithParam<Case> {};

TEST_P(ConvergenceOrder, IsTwo) {
  const Case c = GetParam();
  const CompiledScene scene = loadScene(scenePath(c.scene), c.variable);
  const Eigen::VectorXd reference = finalState(*scene.model, c.scheme, kReferenceStep);
  std::vector<double> dts(std::begin(kSteps), std::end(kSteps)), errors;
  for (double dt : dts)
    errors.push_back((finalState(*scene.model, c.scheme, dt) - reference).lpNorm<Eigen::Infinity>());
  const double order = logLogSlope(dts, errors);
  std::printf("%s on %s: errors", c.label, c.scene);
  for (double e : errors) std::printf(" %.3e", e);
  std::printf(", observed order %.3f\n", order);
  EXPECT_NEAR(order, 2.0, 0.1);
}

INSTANTIATE_TEST_SUITE_P(
    Integrators, ConvergenceOrder,
    ::testing::Values(Case{"two_thermo_springs.xml", Scheme::Eem, ThermalVariable::Entropy, "eem-entropy"},
                      Case{"two_thermo_springs.xml", Scheme::Eem, ThermalVariable::Temperature, "eem-temperature"},
                      Case{"two_thermo_springs.xml", Scheme::Midpoint, ThermalVariable::Temperature, "midpoint"},
                      Case{"two_thermo_springs.xml", Scheme::Trapezoidal, ThermalVariable::Temperature, "trapezoidal"},
                      Case{"thermo_visco_elastic.xml", Scheme::Eem, ThermalVariable::Entropy, "eem-entropy"},
                      Case{"thermo_visco_elastic.xml", Scheme::Eem, ThermalVariable::Temperature, "eem-temperature"},
                      Case{"thermo_visco_elastic.xml", Scheme::Midpoint, ThermalVariable::Temperature, "midpoint"},
                      Case{"thermo_visco_elastic.xml", Scheme::Trapezoidal, ThermalVariable::Temperature,
                           "trapezoidal"}));

// A mass on a spring pushed by a hat load whose kinks (0.3725, 0.745) fall inside a step at
// every size tried. A step's polynomial cannot follow a kink: an eem4 step across one errs by
// O(dt^2), as much as a second-order scheme. The fixed steps end on both kinks as well as on
// every multiple of dt, and eem4 keeps order 4 against IDA at rtol 1e-11.
TEST(FixedStepsAcrossKinks, EndOnTheKinksAndKeepOrderFour) {
  constexpr double kKinkEndTime = 1.5;
  const CompiledScene scene =
      pushedSpring(0.01, kKinkEndTime, Vec3(1, 0.5, 0), {{"profile", "hat"}, {"period", 0.745}});
  ASSERT_EQ(scene.model->loadBreakpoints(), (std::vector<double>{0.3725, 0.745}));
  const History ida = runIda(*scene.model, 1e-11, kKinkEndTime, false, kKinkEndTime);
  ASSERT_FALSE(ida.summary.failed) << ida.summary.failure;
  const Eigen::Index compared = scene.model->layout().offset(Block::Multiplier);
  std::vector<double> dts(std::begin(kSteps), std::end(kSteps)), errors;
  std::printf("eem4 across kinks: errors");
  for (double dt : dts) {
    const History h = run(*scene.model, Scheme::Eem4, dt, kKinkEndTime);
    ASSERT_FALSE(h.summary.failed) << h.summary.failure;
    // one step more per kink; every other step ends on a multiple of dt, or on t_end
    const std::size_t nominal = static_cast<std::size_t>(std::ceil(kKinkEndTime / dt - 1e-9));
    EXPECT_EQ(h.time.size() - 1, nominal + 2) << "dt " << dt;
    for (double kink : {0.3725, 0.745})
      EXPECT_NE(std::find(h.time.begin(), h.time.end(), kink), h.time.end()) << "no step ends at " << kink;
    for (double t : h.time)
      if (t != 0.3725 && t != 0.745 && t != kKinkEndTime) {
        EXPECT_NEAR(t / dt, std::round(t / dt), 1e-9) << "dt " << dt;
      }
    errors.push_back((h.states.back() - ida.states.back()).head(compared).lpNorm<Eigen::Infinity>());
    std::printf(" %.3e", errors.back());
  }
  const double order = logLogSlope(dts, errors);
  std::printf(", observed order %.3f\n", order);
  EXPECT_NEAR(order, 4.0, 0.3);
}

// Two breakpoints in one step (a hat of period 0.1 at dt 0.13) are both step ends, and the
// step still ends on its multiple of dt; a run of 20000 steps takes 20000, although the time
// summed step by step falls short of t_end by more than the 1e-9 dt a remainder may have, and
// its last step spans what remains to t_end.
TEST(FixedStepsAcrossKinks, EndOnEveryBreakpointAndCountTheirSteps) {
  const CompiledScene scene = pushedSpring(0.13, 0.39, Vec3(1, 0.5, 0), {{"profile", "hat"}, {"period", 0.1}});
  const History h = run(*scene.model, Scheme::Eem4, 0.13, 0.39);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  ASSERT_EQ(h.time.size(), 6u);
  EXPECT_EQ(h.time[1], 0.05);
  EXPECT_EQ(h.time[2], 0.1);
  EXPECT_EQ(h.time[3], 0.13);
  EXPECT_EQ(h.time.back(), 0.39);
  // the balance closes to round-off of the spring's energy scale k L^2 = 40 J
  EXPECT_LT(maxBalanceDrift(h), 1e-14);

  const CompiledScene free = loadScene(scenePath("two_thermo_springs.xml"));
  const History longRun = run(*free.model, Scheme::Eem, 0.01, 200.0);
  ASSERT_FALSE(longRun.summary.failed) << longRun.summary.failure;
  EXPECT_EQ(longRun.time.size() - 1, 20000u);
  EXPECT_EQ(longRun.time.back(), 200.0);
  EXPECT_EQ(longRun.dt.back(), 200.0 - longRun.time[longRun.time.size() - 2]);
}

// A breakpoint 1e-6 of a step past a multiple of dt (a hat's end at 0.6000001, dt 0.1) leaves a
// sliver of a step before it. eem4's predictor adds the last step's stage miss scaled to the new
// step; from the sliver that scaling (1e18) would turn a round-off miss into a wrong start, and
// the step after it took more Newton iterations than any other. It takes no more than the steps
// before the breakpoint.
TEST(FixedStepsAcrossKinks, ASliverLeavesTheNextPredictionAlone) {
  const CompiledScene scene = pushedSpring(0.1, 1.0, Vec3(1, 0.5, 0), {{"profile", "hat"}, {"period", 0.6000001}});
  const History h = run(*scene.model, Scheme::Eem4, 0.1, 1.0);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  const auto sliver = std::find(h.time.begin(), h.time.end(), 0.6000001);
  ASSERT_NE(sliver, h.time.end());
  const std::size_t k = static_cast<std::size_t>(sliver - h.time.begin());
  ASSERT_LT(h.dt[k], 1e-6);
  const int elsewhere = *std::max_element(h.newtonIterations.begin() + 1, h.newtonIterations.begin() + k - 1);
  EXPECT_LE(h.newtonIterations[k + 1], elsewhere) << "the step after the sliver";
}

}  // namespace
}  // namespace mpx::test
