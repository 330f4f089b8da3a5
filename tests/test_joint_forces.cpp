// Dissipative joints under EEM: with the losses leaving the system, E falls monotonically and
// E + dissipated is conserved; with every loss heating a reservoir, the isolated system keeps
// E exactly and its entropy never decreases.
#include "support.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace mpx::test {
namespace {

// A double pendulum whose hinge carries a Maxwell branch, damping and friction, and whose
// elbow carries a torsional spring with damping; `heatNode` sends every loss into a reservoir.
std::string dampedPendulum(bool heatNode) {
  const std::string heat = heatNode ? R"( heat_node="bearing")" : "";
  return R"(<metriplex name="damped">
    <simulation dt="0.01" t_end="5" thermal_variable="temperature"/>
    <constraints enforcement="augmented_lagrangian" stiffness="1e4"/>
    <gravity g="0 0 -9.81"/>
    <anchor name="ground" position="0 0 0"/>
    <body name="link1" mass="1" inertia="0.001667 0.08417 0.08417" position="0.5 0 0"/>
    <body name="link2" mass="1" inertia="0.001667 0.08417 0.08417" position="1.5 0 0" angular_velocity="0 2 0"
          velocity="0 0 -1"/>
    <joint name="hinge" type="revolute" a="ground" b="link1" anchor="0 0 0" axis="0 1 0"/>
    <joint name="elbow" type="revolute" a="link1" b="link2" anchor="1 0 0" axis="0 1 0"/>
    <reservoir name="bearing" heat_capacity="0.5" reference_temperature="300" temperature="300"/>
    <joint_force name="hinge_losses" joint="hinge" damping="0.2" friction="0.05" friction_velocity="0.01"
                 branch_stiffness="3" viscosity="0.5")" +
         heat + R"(/>
    <joint_force name="elbow_spring" joint="elbow" stiffness="5" rest="0.3" damping="0.1")" +
         heat + R"(/>
  </metriplex>)";
}

History runDamped(bool heatNode) {
  const CompiledScene scene = loadSceneText(dampedPendulum(heatNode), "damped");
  History h = run(*scene.model, Scheme::Eem, scene.settings.dt, scene.settings.tEnd);
  EXPECT_FALSE(h.summary.failed) << h.summary.failure;
  return h;
}

TEST(DissipativeJoints, EnergyFallsAndEnergyPlusDissipatedIsConserved) {
  const History h = runDamped(false);
  const double scale = std::abs(h.energy.front()) + h.dissipated.back();
  for (std::size_t n = 1; n < h.energy.size(); ++n) {
    ASSERT_LE(h.energy[n], h.energy[n - 1] + 1e-14 * scale) << "step " << n;
    ASSERT_NEAR(h.energy[n] + h.dissipated[n], h.energy[0], 1e-10 * scale) << "step " << n;
  }
  EXPECT_GT(h.dissipated.back(), 0.1);  // the losses are not negligible
}

TEST(DissipativeJoints, HeatingAReservoirKeepsEnergyAndProducesEntropy) {
  const History h = runDamped(true);
  const double scale = std::abs(h.energy.front());
  for (std::size_t n = 1; n < h.energy.size(); ++n) {
    ASSERT_NEAR(h.energy[n], h.energy[0], 1e-10 * scale) << "step " << n;
    ASSERT_GE(h.entropy[n] - h.entropy[n - 1], -1e-14 * std::abs(h.entropy[n])) << "step " << n;
  }
  EXPECT_EQ(h.dissipated.back(), 0.0);
  EXPECT_GT(h.entropy.back() - h.entropy.front(), 1e-4);
}

// Two free bodies on a spherical joint with a viscoelastic bushing (spring, damper and Maxwell
// branch on the relative rotation): E + dissipated and both momenta are invariants.
TEST(DissipativeJoints, BushingKeepsMomentaAndTheEnergyBalance) {
  const CompiledScene scene = loadSceneText(R"(<metriplex name="bushing">
    <simulation dt="0.01" t_end="5"/>
    <body name="a" mass="1" inertia="0.02 0.03 0.04" position="0 0 0" angular_velocity="0.5 -1 2"/>
    <body name="b" mass="2" inertia="0.05 0.04 0.03" position="0.6 0 0" velocity="0 0 1"
          angular_velocity="-1 0.5 0.2"/>
    <joint name="ball" type="spherical" a="a" b="b" anchor="0.3 0 0"/>
    <joint_force name="bushing" joint="ball" stiffness="2" damping="0.05" branch_stiffness="1" viscosity="0.2"/>
  </metriplex>)",
                                            "bushing");
  const History h = run(*scene.model, Scheme::Eem, scene.settings.dt, scene.settings.tEnd);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  const double scale = std::abs(h.energy.front());
  for (std::size_t n = 1; n < h.energy.size(); ++n) {
    ASSERT_NEAR(h.energy[n] + h.dissipated[n], h.energy[0], 1e-10 * scale) << "step " << n;
    ASSERT_LE((h.momentum[n] - h.momentum[0]).norm(), 1e-10 * h.momentum[0].norm()) << "step " << n;
    ASSERT_LE((h.angularMomentum[n] - h.angularMomentum[0]).norm(), 1e-10 * h.angularMomentum[0].norm())
        << "step " << n;
  }
  EXPECT_GT(h.dissipated.back(), 1e-3 * scale);
}

}  // namespace
}  // namespace mpx::test
