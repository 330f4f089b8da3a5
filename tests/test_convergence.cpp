// Observed order of convergence: the log-log slope of the error at a fixed time against a
// fine reference of the same integrator is 2 (+- 0.1) for EEM with either thermal variable,
// the implicit midpoint rule and the trapezoidal rule.
#include "support.hpp"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace mpx::test
