// Hard cases (ctest label `hard`): steps far beyond the stiffest period with large temperature
// differences. EEM stays bounded, conserves E exactly and keeps S non-decreasing, with Newton
// converging (through cut-backs where needed); the standard methods blow up. The table each
// test prints is what docs/performance.md records.
#include "support.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace mpx::test {
namespace {

// Outcome of one run: the largest relative energy error, or failure.
struct Outcome {
  bool failed;
  double energyError;
  int cutbacks;
  double meanNewton;
  bool entropyMonotone;
  bool blewUp;  // Newton gave up or the balance is off by more than kBlowUpEnergyError
};

Outcome runCase(const std::string& scene, Scheme scheme, ThermalVariable variable, double dt, double tEnd) {
  const CompiledScene compiled = loadScene(scenePath(scene), variable);
  const History h = run(*compiled.model, scheme, dt, tEnd, compiled.settings.newton);
  return {h.summary.failed,
          relativeBalanceDrift(h),
          h.summary.cutbacks,
          h.summary.steps ? double(h.summary.newtonIterations) / h.summary.steps : 0.0,
          firstEntropyDecrease(h) < 0,
          blewUp(h)};
}

struct HardCase {
  const char* scene;
  double tEnd;
  std::vector<double> steps;
  double standardMethodsFailFrom;  // both standard methods blow up at this step and above
};

class HardCases : public ::testing::TestWithParam<HardCase> {};

TEST_P(HardCases, EemStaysExactWhereStandardMethodsBlowUp) {
  const HardCase c = GetParam();
  std::printf("%s, t_end %g: relative energy error (cut-backs, Newton per step)\n", c.scene, c.tEnd);
  std::printf("%8s %26s %26s %26s %26s\n", "dt", "eem-entropy", "eem-temperature", "midpoint", "trapezoidal");
  for (double dt : c.steps) {
    const Outcome eemS = runCase(c.scene, Scheme::Eem, ThermalVariable::Entropy, dt, c.tEnd);
    const Outcome eemT = runCase(c.scene, Scheme::Eem, ThermalVariable::Temperature, dt, c.tEnd);
    const Outcome mid = runCase(c.scene, Scheme::Midpoint, ThermalVariable::Temperature, dt, c.tEnd);
    const Outcome trap = runCase(c.scene, Scheme::Trapezoidal, ThermalVariable::Temperature, dt, c.tEnd);
    auto cell = [](const Outcome& o) {
      char text[64];
      std::snprintf(text, sizeof text, "%s%.1e (%d, %.1f)", o.failed ? "FAILED " : "", o.energyError, o.cutbacks,
                    o.meanNewton);
      return std::string(text);
    };
    std::printf("%8g %26s %26s %26s %26s\n", dt, cell(eemS).c_str(), cell(eemT).c_str(), cell(mid).c_str(),
                cell(trap).c_str());
    for (const Outcome* eem : {&eemS, &eemT}) {
      EXPECT_FALSE(eem->failed) << "dt " << dt;
      EXPECT_LE(eem->energyError, 1e-12) << "dt " << dt;
      EXPECT_TRUE(eem->entropyMonotone) << "dt " << dt;
    }
    if (dt >= c.standardMethodsFailFrom) {
      EXPECT_TRUE(mid.blewUp) << "midpoint at dt " << dt;
      EXPECT_TRUE(trap.blewUp) << "trapezoidal at dt " << dt;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(StiffAndLargeSteps, HardCases,
                         ::testing::Values(
                             // stiffness ratio 1e4, temperatures 0.5 to 5; stiff period 0.063
                             HardCase{"stiff_thermo_chain.xml", 50.0, {0.01, 0.05, 0.1, 0.25, 0.5, 1.0}, 0.1},
                             // steps up to beyond the fast period (about 2 pi) of the two thermo-spring system
                             HardCase{"two_thermo_springs.xml", 400.0, {0.5, 1.0, 2.0, 4.0, 8.0}, 2.0}),
                         [](const ::testing::TestParamInfo<HardCase>& info) {
                           const std::string scene = info.param.scene;
                           return scene.substr(0, scene.find('.'));
                         });

}  // namespace
}  // namespace mpx::test
