// Two-point elements at body points (a_point, b_point): a point phi + X_i d_i is linear in the
// body's dofs, so EEM keeps the energy balance to round-off on tumbling bodies, a force along
// the line between two body points keeps linear and angular momentum, dissipative elements at
// points produce entropy, and an actuator's work is counted. Also the input errors.
#include "support.hpp"

#include "engine/core/input_error.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace mpx::test {
namespace {

// Two tumbling free bodies (products of inertia, turned), no gravity.
const char* const kTwoBodies = R"(
    <body name="left" mass="2" inertia="0.2 0.3 0.4 0.03 -0.02 0.01" orientation="0.9 0.1 0.3 -0.2"
          position="0 0 0" velocity="0.1 0.2 -0.1" angular_velocity="1 2 3"/>
    <body name="right" mass="1.5" inertia="0.15 0.1 0.2" orientation="0.8 -0.3 0.1 0.5"
          position="1.2 0.1 -0.1" velocity="-0.2 0 0.1" angular_velocity="-2 0.5 1"/>)";

SceneRun runScene(const std::string& body, double dt, int steps) {
  CompiledScene scene =
      loadSceneText("<metriplex><simulation dt=\"" + std::to_string(dt) + "\" t_end=\"100\"/>" + body + "</metriplex>",
                    "body_points");
  History h = run(*scene.model, Scheme::Eem, dt, steps * dt, scene.settings.newton);
  return {std::move(scene), std::move(h)};
}

// max_n max_i |v_n,i - v_0,i| / |v_0|
double componentDrift(const std::vector<Vec3>& series) {
  double drift = 0.0;
  for (const Vec3& v : series)
    drift = std::max(drift, (v - series.front()).cwiseAbs().maxCoeff() / series.front().norm());
  return drift;
}

// A body hung from an anchor by a spring at one of its corners, tumbling in gravity.
TEST(BodyPoints, SpringAtACornerKeepsTheEnergyOfATumblingBody) {
  const SceneRun r = runScene(R"(<gravity g="0 0 -9.81"/>
    <anchor name="hook" position="0 0 1"/>
    <body name="block" mass="2" inertia="0.2 0.3 0.4 0.03 -0.02 0.01" orientation="0.9 0.1 0.3 -0.2"
          position="0.1 0 0" velocity="0.1 0.2 -0.1" angular_velocity="1 2 3"/>
    <spring name="hang" a="hook" b="block" b_point="0.3 0.2 0.15" stiffness="200" rest_length="0.8"/>)",
                              0.01, 1000);
  const History& h = r.history;
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  std::printf("spring at a corner, 1000 EEM steps: balance drift %.2e of %.3g J\n", maxBalanceDrift(h),
              largestEnergy(h));
  EXPECT_LE(maxBalanceDrift(h), 1e-11 * largestEnergy(h));
  // the spring really turns the body: its spin, the angular momentum about its centre, changes
  // (gravity, or a spring at the centre, would leave it as it was)
  const int centre = r.scene.bodies.front().firstPositionDof;
  auto spin = [&](std::size_t n) {
    return Vec3(h.angularMomentum[n] - Vec3(h.states[n].segment<3>(centre)).cross(h.momentum[n]));
  };
  std::printf("spin %.3f -> %.3f N m s\n", spin(0).norm(), spin(h.states.size() - 1).norm());
  EXPECT_GT((spin(h.states.size() - 1) - spin(0)).norm(), 0.1);
}

// Spring, damper and Maxwell element between off-centre points of two free bodies: internal
// forces along the line between the points, so P and L stay, and E + dissipated is exact.
TEST(BodyPoints, ForcesBetweenTwoBodiesKeepMomentaExactly) {
  const SceneRun r = runScene(std::string(kTwoBodies) + R"(
    <spring name="spring" a="left" a_point="0.2 0.1 0.05" b="right" b_point="1.0 -0.05 0.1" stiffness="50"
            rest_length="0.6"/>
    <damper name="damper" a="left" a_point="-0.1 0.15 0" b="right" b_point="1.3 0.2 -0.2" coefficient="0.8"/>
    <maxwell name="maxwell" a="right" b_point="1.1 0 -0.15" b="left" stiffness="10" rest_length="1"
             branch_stiffness="20" viscosity="0.5"/>)",
                              0.01, 1000);
  const History& h = r.history;
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  std::printf("two bodies, 1000 EEM steps: drift of P %.2e, L %.2e, balance %.2e (dissipated %.3g J of %.3g J)\n",
              componentDrift(h.momentum), componentDrift(h.angularMomentum), maxBalanceDrift(h), h.dissipated.back(),
              largestEnergy(h));
  EXPECT_LE(componentDrift(h.momentum), 1e-12);
  EXPECT_LE(componentDrift(h.angularMomentum), 1e-12);
  EXPECT_LE(maxBalanceDrift(h), 1e-11 * largestEnergy(h));
  EXPECT_GT(h.dissipated.back(), 1e-3 * largestEnergy(h));
}

// Thermo elements at body points heat their own nodes: E stays, S never falls.
TEST(BodyPoints, ThermoElementsAtPointsProduceEntropy) {
  const SceneRun r = runScene(std::string(kTwoBodies) + R"(
    <thermo_maxwell name="visco" a="left" a_point="0.2 0.1 0.05" b="right" b_point="1.0 -0.05 0.1"
                    stiffness="5" stiffness_slope="-0.1" coupling="0.5" rest_length="0.6" heat_capacity="1"
                    reference_temperature="1" branch_stiffness="8" viscosity="0.3" viscosity_activation="0.5"
                    temperature="1"/>
    <thermo_spring name="thermo" a="left" a_point="-0.1 0.15 0" b="right" stiffness="3" coupling="0.2"
                   rest_length="1" heat_capacity="2" reference_temperature="1" temperature="1.1"/>
    <heat_link name="link" a="visco" b="thermo" conductivity="0.5"/>)",
                              0.01, 1000);
  const History& h = r.history;
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  std::printf("thermo elements at points, 1000 EEM steps: E drift %.2e, S gained %.3g, P %.2e, L %.2e\n",
              maxBalanceDrift(h) / largestEnergy(h), h.entropy.back() - h.entropy.front(), componentDrift(h.momentum),
              componentDrift(h.angularMomentum));
  EXPECT_EQ(firstEntropyDecrease(h), -1);
  EXPECT_GT(h.entropy.back() - h.entropy.front(), 1e-4);
  EXPECT_LE(maxBalanceDrift(h), 1e-11 * largestEnergy(h));
  EXPECT_LE(componentDrift(h.momentum), 1e-12);
  EXPECT_LE(componentDrift(h.angularMomentum), 1e-12);
}

// An actuator pushing a body point away from an anchor (ramped up and down) against a damper:
// E - E0 = external work - dissipated, exactly.
TEST(BodyPoints, ActuatorWorkEntersTheBalance) {
  const SceneRun r = runScene(R"(<gravity g="0 0 -9.81"/>
    <anchor name="base" position="0 0 -1"/>
    <body name="block" mass="2" inertia="0.2 0.3 0.4" orientation="0.9 0.1 0.3 -0.2" angular_velocity="0 1 0"/>
    <joint name="ball" type="spherical" a="base" b="block" anchor="0 0 -0.5"/>
    <anchor name="wall" position="1 0 0"/>
    <actuator name="push" a="wall" b="block" b_point="0.2 0 0.3" force="20" profile="hat" period="2"/>
    <damper name="loss" a="wall" b="block" b_point="0.1 0.1 0.2" coefficient="2"/>)",
                              0.005, 600);
  const History& h = r.history;
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  std::printf("actuator, 600 EEM steps: work %.4g J, dissipated %.4g J, balance drift %.2e\n", h.externalWork.back(),
              h.dissipated.back(), maxBalanceDrift(h));
  EXPECT_GT(std::abs(h.externalWork.back()), 0.1);
  EXPECT_GT(h.dissipated.back(), 1e-3);
  EXPECT_LE(maxBalanceDrift(h), 1e-11 * largestEnergy(h));
}

// Two actuators pulling two free bodies together keep P and L (internal forces).
TEST(BodyPoints, ActuatorBetweenBodiesKeepsMomenta) {
  const SceneRun r = runScene(std::string(kTwoBodies) + R"(
    <actuator name="pull" a="left" a_point="0.2 0.1 0.05" b="right" b_point="1.0 -0.05 0.1" force="-3"
              profile="sine_pulse" duration="1"/>)",
                              0.01, 200);
  const History& h = r.history;
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  std::printf("actuator between bodies, 200 EEM steps: work %.4g J\n", h.externalWork.back());
  // the actuator does work (without it the bodies would keep P and L all the same)
  EXPECT_GT(std::abs(h.externalWork.back()), 0.1);
  EXPECT_LE(componentDrift(h.momentum), 1e-12);
  EXPECT_LE(componentDrift(h.angularMomentum), 1e-12);
  EXPECT_LE(maxBalanceDrift(h), 1e-11 * largestEnergy(h));
}

// What a body point cannot be, with the element's line in the message.
std::string errorOf(const std::string& elements) {
  const std::string bodies = R"(<mass name="m" mass="1" position="1 0 0"/>
    <anchor name="pivot"/>
    <body name="block" mass="1" inertia="1 1 1" position="0 1 0"/>
    <body name="other" mass="1" inertia="1 1 1" position="0 3 0"/>
)";
  try {
    loadSceneText("<metriplex><simulation dt=\"0.01\" t_end=\"1\"/>\n" + bodies + elements + "</metriplex>",
                  "scene.xml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expectError(const std::string& elements, const std::string& fragment) {
  const std::string message = errorOf(elements);
  EXPECT_NE(message.find(fragment), std::string::npos) << message;
}

TEST(BodyPoints, PointsOnlyOnBodies) {
  expectError(R"(<spring name="s" a="m" a_point="1 0 0" b="block" stiffness="1" rest_length="1"/>)",
              "scene.xml:6: <spring name=\"s\">: attribute 'a_point': 'm' is not a body");
  expectError(R"(<damper name="d" a="block" b="pivot" b_point="0 0 1" coefficient="1"/>)",
              "attribute 'b_point': 'pivot' is not a body");
  expectError(R"(<spring name="s" a="block" a_point="0 1 1" b="block" stiffness="1" rest_length="1"/>)",
              "on the same body");
  expectError(R"(<actuator name="f" a="block" a_point="0 3 0" b="other" force="1"/>)", "coincide");
  EXPECT_EQ(errorOf(R"(<actuator name="f" a="block" a_point="0 2 0" b="other" force="1"/>)"), "");
}

}  // namespace
}  // namespace mpx::test
