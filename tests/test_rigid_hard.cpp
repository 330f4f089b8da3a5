// Hard rigid-body cases (ctest label `hard`): every constraint (joints and director rigidity)
// as a penalty of stiffness 1e10, i.e. 1e10 times the scale of these bodies (masses of about
// 1 kg, lengths of about 1 m, so kappa in N/m against m g / L ~ 10 N/m), at steps far beyond the
// penalty periods. EEM keeps E (+ dissipated) to 1e-9 and never fails, cutting steps back
// where Newton needs it; the implicit midpoint rule fails or drifts. The table each case
// prints gives the step sizes at which each integrator fails.
#include "support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <ostream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace mpx::test {
namespace {

constexpr double kPenaltyStiffness = 1e10;

// The scene default that makes every constraint a penalty of kPenaltyStiffness.
std::string penaltyConstraints() {
  char element[96];
  std::snprintf(element, sizeof element, R"(<constraints enforcement="penalty" stiffness="%g"/>)", kPenaltyStiffness);
  return element;
}

// A scene file with its <constraints> default replaced by penaltyConstraints().
std::string penaltyVariant(const char* file) {
  std::ifstream in(scenePath(file));
  std::stringstream text;
  text << in.rdbuf();
  return std::regex_replace(text.str(), std::regex("<constraints[^>]*/>"), penaltyConstraints());
}

// Five free 1 kg, 1 m links in a row joined by spherical, revolute (z), spherical and universal
// joints, no gravity; link1 swings at 30 rad/s about the joint at its far end (1, 0, 0) while
// the others rest (consistent with every joint): the motion runs down the chain and cracks its
// tip like a whip.
std::string whippingChain() {
  std::string bodies, joints;
  const char* kinds[] = {R"(type="spherical")", R"(type="revolute" axis="0 0 1")", R"(type="spherical")",
                         R"(type="universal" axis="0 0 1" axis_b="0 1 0")"};
  for (int i = 1; i <= 5; ++i) {
    const std::string motion = i == 1 ? R"( velocity="0 -15 0" angular_velocity="0 0 30")" : "";
    bodies += "<body name=\"link" + std::to_string(i) + R"(" mass="1" inertia="0.001667 0.08417 0.08417" position=")" +
              std::to_string(i - 0.5) + " 0 0\"" + motion + "/>\n";
  }
  for (int i = 1; i <= 4; ++i)
    joints += "<joint name=\"joint" + std::to_string(i) + "\" " + kinds[i - 1] + " a=\"link" + std::to_string(i) +
              "\" b=\"link" + std::to_string(i + 1) + "\" anchor=\"" + std::to_string(i) + " 0 0\"/>\n";
  return R"(<metriplex name="whipping_chain"><simulation dt="0.01" t_end="1"/>)" + penaltyConstraints() + bodies +
         joints + "</metriplex>";
}

// Outcome of one run: the largest relative energy balance error max |E + D - E_0| / |E_0|.
struct Outcome {
  bool failed;
  double energyError;
  int cutbacks;
  double meanNewton;
  bool blewUp;  // Newton gave up or the balance is off by more than kBlowUpEnergyError
};

Outcome runCase(const std::string& sceneText, Scheme scheme, double dt, double tEnd) {
  const CompiledScene scene = loadSceneText(sceneText, "hard case");
  // default Newton settings: a scene's relaxed tolerances are meant for its multipliers, and
  // these variants have none
  const History h = run(*scene.model, scheme, dt, tEnd, NewtonSettings{});
  return {h.summary.failed, relativeBalanceDrift(h), h.summary.cutbacks,
          h.summary.steps ? double(h.summary.newtonIterations) / h.summary.steps : 0.0, blewUp(h)};
}

struct HardCase {
  const char* name;
  std::string (*sceneText)();
  double tEnd;
  std::vector<double> steps;
  double midpointFailsFrom;  // the midpoint rule blows up at this step and above
};

void PrintTo(const HardCase& c, std::ostream* out) { *out << c.name; }

class RigidHardCases : public ::testing::TestWithParam<HardCase> {};

TEST_P(RigidHardCases, EemStaysExactWhereMidpointFailsOrDrifts) {
  const HardCase c = GetParam();
  const std::string scene = c.sceneText();
  std::printf("%s, penalty stiffness %g, t_end %g: relative energy error (cut-backs, Newton per step)\n", c.name,
              kPenaltyStiffness, c.tEnd);
  std::printf("%8s %26s %26s %26s\n", "dt", "eem", "midpoint", "trapezoidal");
  for (double dt : c.steps) {
    const Outcome eem = runCase(scene, Scheme::Eem, dt, c.tEnd);
    const Outcome mid = runCase(scene, Scheme::Midpoint, dt, c.tEnd);
    const Outcome trap = runCase(scene, Scheme::Trapezoidal, dt, c.tEnd);
    auto cell = [](const Outcome& o) {
      char text[64];
      std::snprintf(text, sizeof text, "%s%.1e (%d, %.1f)", o.failed ? "FAILED " : "", o.energyError, o.cutbacks,
                    o.meanNewton);
      return std::string(text);
    };
    std::printf("%8g %26s %26s %26s\n", dt, cell(eem).c_str(), cell(mid).c_str(), cell(trap).c_str());
    EXPECT_FALSE(eem.failed) << "dt " << dt;
    EXPECT_LE(eem.energyError, 1e-9) << "dt " << dt;
    if (dt >= c.midpointFailsFrom) {
      EXPECT_TRUE(mid.blewUp) << "midpoint at dt " << dt;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    StiffPenalties, RigidHardCases,
    ::testing::Values(HardCase{"double_pendulum",
                               [] { return penaltyVariant("double_pendulum_penalty.xml"); },
                               2.0,
                               {0.001, 0.005, 0.01, 0.05},
                               0.001},
                      // at dt 0.001 the midpoint rule's error (about 11 %) is on the edge of "blown up"
                      HardCase{"flyball_governor",
                               [] { return penaltyVariant("flyball_governor.xml"); },
                               0.5,
                               {0.001, 0.005, 0.01, 0.05},
                               0.005},
                      HardCase{"whipping_chain", whippingChain, 1.0, {0.002, 0.01, 0.05}, 0.002}),
    [](const ::testing::TestParamInfo<HardCase>& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace mpx::test
