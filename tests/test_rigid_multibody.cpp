// Rigid multibody systems (bodies as centre of mass plus directors, joints as quadratic
// constraints) under EEM: energy, linear and angular momentum kept to round-off, constraints
// held to round-off by the augmented Lagrangian and to O(1/kappa) by penalties, and the
// assembled step tangent consistent with its residual for every joint type.
#include "support.hpp"
#include "tangent_check.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <random>
#include <string>
#include <vector>

namespace mpx::test {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// `steps` steps of the scene's own dt with the scene's Newton settings.
SceneRun runSteps(CompiledScene scene, Scheme scheme, int steps) {
  const SceneSettings& s = scene.settings;
  History h = run(*scene.model, scheme, s.dt, steps * s.dt, s.newton);
  return {std::move(scene), std::move(h)};
}

// max_n |E_n - E_0| / |E_0|
double energyDrift(const History& h) {
  double drift = 0.0;
  for (double e : h.energy) drift = std::max(drift, std::abs(e - h.energy.front()) / std::abs(h.energy.front()));
  return drift;
}

// max_n max_i |v_n,i - v_0,i| / |v_0|: every component against the initial magnitude.
double componentDrift(const std::vector<Vec3>& series) {
  double drift = 0.0;
  for (const Vec3& v : series)
    drift = std::max(drift, (v - series.front()).cwiseAbs().maxCoeff() / series.front().norm());
  return drift;
}

// Measures::constraintViolation (max |Phi|) of every recorded state.
std::vector<double> violations(const Model& model, const History& h) {
  Measures measures;
  std::vector<double> out;
  for (const VectorXd& z : h.states) {
    model.measure(z, measures);
    out.push_back(measures.constraintViolation);
  }
  return out;
}

double maxViolation(const Model& model, const History& h) {
  const std::vector<double> v = violations(model, h);
  return *std::max_element(v.begin(), v.end());
}

// ---------------------------------------------------------------------------------------------
// The double pendulum with augmented Lagrangian and with penalty constraints, 10^4 EEM steps
// (100 s of motion). Midpoint runs its first 200 steps only: with penalties it needs hundreds of
// cut-backs afterwards (about 6 s for 2000 steps) and has long lost the energy by then.
constexpr int kPendulumSteps = 10000;
constexpr int kMidpointSteps = 200;
constexpr double kEnergyTolerance = 1e-10;

class DoublePendulum : public ::testing::TestWithParam<const char*> {};

TEST_P(DoublePendulum, EemKeepsTheEnergyWhereMidpointLosesIt) {
  const SceneRun eem = runSteps(loadScene(scenePath(GetParam())), Scheme::Eem, kPendulumSteps);
  ASSERT_FALSE(eem.history.summary.failed) << eem.history.summary.failure;
  EXPECT_LE(energyDrift(eem.history), kEnergyTolerance);

  const SceneRun midpoint = runSteps(loadScene(scenePath(GetParam())), Scheme::Midpoint, kMidpointSteps);
  const double midpointDrift = energyDrift(midpoint.history);
  std::printf("%s, dt %g: relative energy error EEM %.2e (%d steps), midpoint %.2e (%d steps)%s\n", GetParam(),
              eem.scene.settings.dt, energyDrift(eem.history), kPendulumSteps, midpointDrift,
              midpoint.history.summary.steps, midpoint.history.summary.failed ? ", midpoint FAILED" : "");
  EXPECT_TRUE(midpoint.history.summary.failed || midpointDrift > 1e6 * kEnergyTolerance) << midpointDrift;
}

INSTANTIATE_TEST_SUITE_P(BothEnforcements, DoublePendulum,
                         ::testing::Values("double_pendulum.xml", "double_pendulum_penalty.xml"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                           const std::string file = info.param;
                           return file.substr(0, file.find('.'));
                         });

// ---------------------------------------------------------------------------------------------
// Nothing acts on the free-floating chain from outside: both momenta are invariants.
TEST(FreeFloatingChain, EemConservesLinearAndAngularMomentum) {
  const SceneRun r = runSteps(loadScene(scenePath("free_floating_chain.xml")), Scheme::Eem, 200);
  ASSERT_FALSE(r.history.summary.failed) << r.history.summary.failure;
  EXPECT_LE(componentDrift(r.history.momentum), 1e-10);
  EXPECT_LE(componentDrift(r.history.angularMomentum), 1e-10);
  EXPECT_LE(energyDrift(r.history), kEnergyTolerance);
  std::printf("free-floating chain, 200 steps: drift of P %.2e, L %.2e, E %.2e\n", componentDrift(r.history.momentum),
              componentDrift(r.history.angularMomentum), energyDrift(r.history));
}

// ---------------------------------------------------------------------------------------------
// Every joint type between two moving bodies: link1 hinged to the ground about y at the
// origin, link2 joined to link1's tip by the joint under test, released from rest under a
// gravity with components along every axis so that every constraint direction is loaded.
struct JointCase {
  const char* type;
  const char* geometry;  // the joint's anchor/axis attributes
};

void PrintTo(const JointCase& c, std::ostream* out) { *out << c.type; }

const JointCase kJointCases[] = {
    {"spherical", R"(anchor="1 0 0")"},
    {"revolute", R"(anchor="1 0 0" axis="0 0 1")"},
    {"universal", R"(anchor="1 0 0" axis="0 1 0" axis_b="0 0 1")"},
    {"cylindrical", R"(anchor="1 0 0" axis="1 0 0")"},
    {"prismatic", R"(anchor="1 0 0" axis="1 0 0")"},
    {"fixed", R"(anchor="1 0 0")"},
    {"distance", R"(anchor="0.9 0 0" anchor_b="1.1 0 0")"},
};

std::string twoLinksJoinedBy(const JointCase& joint, const std::string& enforcement, double stiffness) {
  return R"(<metriplex name="two_links">
    <simulation dt="0.01" t_end="1"/>
    <constraints enforcement=")" +
         enforcement + R"(" stiffness=")" + std::to_string(stiffness) + R"("/>
    <gravity g="1 -2 -9.81"/>
    <anchor name="ground" position="0 0 0"/>
    <body name="link1" mass="1" inertia="0.001667 0.08417 0.08417" position="0.5 0 0"/>
    <body name="link2" mass="1" inertia="0.001667 0.08417 0.08417" position="1.5 0 0"/>
    <joint name="hinge" type="revolute" a="ground" b="link1" anchor="0 0 0" axis="0 1 0"/>
    <joint name="elbow" type=")" +
         joint.type + R"(" a="link1" b="link2" )" + joint.geometry + R"(/>
    </metriplex>)";
}

constexpr int kJointSteps = 150;

class JointEnforcement : public ::testing::TestWithParam<JointCase> {};

// the multipliers are solved with the positions: the constraints hold to round-off
TEST_P(JointEnforcement, AugmentedLagrangianHoldsEveryStep) {
  const SceneRun r = runSteps(loadSceneText(twoLinksJoinedBy(GetParam(), "augmented_lagrangian", 1e6), GetParam().type),
                              Scheme::Eem, kJointSteps);
  ASSERT_FALSE(r.history.summary.failed) << r.history.summary.failure;
  const std::vector<double> v = violations(*r.scene.model, r.history);
  for (std::size_t n = 0; n < v.size(); ++n) ASSERT_LT(v[n], 1e-10) << "step " << n;
  EXPECT_LE(energyDrift(r.history), kEnergyTolerance);
}

// a penalty yields by about force/kappa: every 100x stiffer penalty at least 10x smaller
TEST_P(JointEnforcement, PenaltyViolationShrinksWithStiffness) {
  std::vector<double> largest;
  for (double stiffness : {1e4, 1e6, 1e8}) {
    const SceneRun r = runSteps(loadSceneText(twoLinksJoinedBy(GetParam(), "penalty", stiffness), GetParam().type),
                                Scheme::Eem, kJointSteps);
    ASSERT_FALSE(r.history.summary.failed) << "stiffness " << stiffness << ": " << r.history.summary.failure;
    EXPECT_LE(energyDrift(r.history), kEnergyTolerance) << "stiffness " << stiffness;
    largest.push_back(maxViolation(*r.scene.model, r.history));
  }
  std::printf("%s, penalty: max violation %.2e, %.2e, %.2e at stiffness 1e4, 1e6, 1e8\n", GetParam().type, largest[0],
              largest[1], largest[2]);
  EXPECT_LT(largest[1], 0.1 * largest[0]);
  EXPECT_LT(largest[2], 0.1 * largest[1]);
}

INSTANTIATE_TEST_SUITE_P(EveryJointType, JointEnforcement, ::testing::ValuesIn(kJointCases),
                         [](const ::testing::TestParamInfo<JointCase>& info) { return std::string(info.param.type); });

// ---------------------------------------------------------------------------------------------
// Gravity and the reaction at the fixed point (the origin) exert no moment about the
// vertical through it: L_z is an invariant of the heavy top, while the top precesses.
TEST(HeavyTop, EemConservesTheVerticalAngularMomentum) {
  const SceneRun r = runSteps(loadScene(scenePath("heavy_top.xml")), Scheme::Eem, 500);
  ASSERT_FALSE(r.history.summary.failed) << r.history.summary.failure;
  const std::vector<Vec3>& L = r.history.angularMomentum;
  double verticalDrift = 0.0, horizontalChange = 0.0;
  for (const Vec3& l : L) {
    verticalDrift = std::max(verticalDrift, std::abs(l.z() - L.front().z()) / std::abs(L.front().z()));
    horizontalChange = std::max(horizontalChange, (l - L.front()).head<2>().norm() / L.front().norm());
  }
  std::printf("heavy top, 500 steps: drift of L_z %.2e, of E %.2e; horizontal L moved by %.2f |L0|\n", verticalDrift,
              energyDrift(r.history), horizontalChange);
  EXPECT_LE(verticalDrift, 1e-10);
  EXPECT_LE(energyDrift(r.history), kEnergyTolerance);
  EXPECT_GT(horizontalChange, 0.1);  // the invariant is not kept by standing still
}

// ---------------------------------------------------------------------------------------------
// A free body (products of inertia, turned, drifting) spinning about no principal axis
// tumbles; E, P and every component of L are invariants and the directors stay orthonormal.
TEST(FreeRigidBody, EemConservesEnergyAndMomentaWhileTumbling) {
  const SceneRun r = runSteps(loadSceneText(R"(<metriplex name="tumbling_body">
    <simulation dt="0.01" t_end="10"/>
    <body name="block" mass="2" inertia="2 3 4 0.3 -0.2 0.1" orientation="0.9 0.1 0.3 -0.2"
          position="0.3 -0.2 0.5" velocity="0.1 0.2 -0.1" angular_velocity="1 2 3"/>
    </metriplex>)",
                                            "tumbling_body"),
                              Scheme::Eem, 1000);
  const History& h = r.history;
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  const double violation = maxViolation(*r.scene.model, h);
  std::printf("free rigid body, 1000 steps: drift of E %.2e, P %.2e, L %.2e; max violation %.2e\n", energyDrift(h),
              componentDrift(h.momentum), componentDrift(h.angularMomentum), violation);
  EXPECT_LE(energyDrift(h), 1e-12);
  EXPECT_LE(componentDrift(h.momentum), 1e-12);
  EXPECT_LE(componentDrift(h.angularMomentum), 1e-12);
  EXPECT_LE(violation, 1e-12);
}

// A torque ramped up over 1 s on a free body: the angular momentum grows by its time integral
// (to O(dt^2): the director forces act at mid-step directors) and E - external work is exact.
TEST(FreeRigidBody, TorqueDrivesTheAngularMomentum) {
  const SceneRun r = runSteps(loadSceneText(R"(<metriplex name="torqued_body">
    <simulation dt="0.001" t_end="2"/>
    <body name="block" mass="2" inertia="2 3 4 0.3 -0.2 0.1" orientation="0.9 0.1 0.3 -0.2" angular_velocity="1 0 0"/>
    <torque name="drive" on="block" torque="0.5 -0.2 1" profile="ramp" start="0" end="1"/>
    </metriplex>)",
                                            "torqued_body"),
                              Scheme::Eem, 2000);
  const History& h = r.history;
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  // integral of the ramp over [0, 2]: 0.5 + 1
  const Vec3 impulse = 1.5 * Vec3(0.5, -0.2, 1.0);
  const Vec3 gained = h.angularMomentum.back() - h.angularMomentum.front();
  std::printf("torqued body: |L gained - impulse| = %.2e\n", (gained - impulse).norm());
  EXPECT_LE((gained - impulse).norm(), 1e-6 * impulse.norm());
  for (std::size_t n = 0; n < h.energy.size(); ++n)
    ASSERT_NEAR(h.energy[n] - h.externalWork[n], h.energy[0], 1e-12 * (h.energy[0] + h.externalWork.back()));
  EXPECT_GT(h.externalWork.back(), 0.1);
}

// ---------------------------------------------------------------------------------------------
// The assembled EEM step tangent against central differences of the step residual
// (the approach of test_tangents.cpp), for bodies joined by every joint type, a mass on a
// distance joint and a spherical joint, a spring and a damper on centres of mass, in gravity.
std::string everyJointType(const std::string& enforcement) {
  return R"(<metriplex name="every_joint">
    <simulation dt="0.1" t_end="1"/>
    <constraints enforcement=")" +
         enforcement + R"(" stiffness="1e3"/>
    <gravity g="0.5 -1 -9.81"/>
    <anchor name="ground" position="0 0 0"/>
    <body name="b1" mass="1" inertia="0.01 0.09 0.09" position="0.5 0 0" angular_velocity="0 0.7 0.2"/>
    <body name="b2" mass="0.8" inertia="0.02 0.03 0.04 0.001 -0.002 0.003" orientation="0.9 0.1 0.3 -0.2"
          position="1.5 0.1 0" velocity="0.1 0.2 -0.3" angular_velocity="0.3 -0.2 0.5"/>
    <body name="b3" mass="1.2" inertia="0.03 0.05 0.06" position="2.5 0 0.1" velocity="0 0.3 0"/>
    <body name="b4" mass="0.6" inertia="0.01 0.02 0.02" orientation="0.8 0 0.6 0" position="3.5 0 0"
          angular_velocity="1 0 0"/>
    <body name="b5" mass="0.9" inertia="0.04 0.04 0.05" position="4.5 0 0" velocity="0.2 0 0.1"/>
    <body name="b6" mass="0.7" inertia="0.02 0.03 0.03" position="5.5 0 0" angular_velocity="0 0 0.4"/>
    <mass name="bob" mass="0.5" position="1 -1 0" velocity="0 0.1 0.2"/>
    <mass name="tip" mass="0.3" position="6 0 0" velocity="0 0 0.3"/>
    <joint name="hinge" type="revolute" a="ground" b="b1" anchor="0 0 0" axis="0 1 0"/>
    <joint name="ball" type="spherical" a="b1" b="b2" anchor="1 0 0"/>
    <joint name="cross" type="universal" a="b2" b="b3" anchor="2 0 0" axis="0 0 1" axis_b="0 1 0"/>
    <joint name="sleeve" type="cylindrical" a="b3" b="b4" anchor="3 0 0" axis="1 0 0"/>
    <joint name="slide" type="prismatic" a="b4" b="b5" anchor="4 0 0" axis="1 0 0.2"/>
    <joint name="weld" type="fixed" a="b5" b="b6" anchor="5 0 0"/>
    <joint name="rope" type="distance" a="b1" b="bob" anchor="0.8 0 0"/>
    <joint name="pin" type="spherical" a="b6" b="tip"/>
    <spring name="spring" a="ground" b="b3" stiffness="20" rest_length="2"/>
    <damper name="damper" a="bob" b="b4" coefficient="0.4"/>
    </metriplex>)";
}

struct TangentCase {
  const char* enforcement;
  double offset;        // zNew = zOld + offset * random: 0 is where Newton starts every step
  double relativeStep;  // finite-difference step relative to each dof's magnitude
};

void PrintTo(const TangentCase& c, std::ostream* out) { *out << c.enforcement << " offset " << c.offset; }

class RigidStepTangent : public ::testing::TestWithParam<TangentCase> {};

TEST_P(RigidStepTangent, MatchesCentralDifferencesOfTheResidual) {
  const TangentCase& c = GetParam();
  const CompiledScene scene = loadSceneText(everyJointType(c.enforcement), "every_joint");
  const Model& model = *scene.model;
  Integrator integrator(model, Scheme::Eem, NewtonSettings{});
  const double t = 0.3, dt = scene.settings.dt;
  // a generic old state, away from the initial constraint manifold and with non-zero multipliers
  const VectorXd& z0 = model.initialState();
  const VectorXd zOld = z0 + 1e-2 * randomIsh(z0.cwiseAbs() + model.dofScale(), 3);
  const VectorXd magnitude = zOld.cwiseAbs() + model.dofScale();
  const VectorXd zNew = zOld + c.offset * randomIsh(magnitude, 7);

  const MatrixXd analytic(integrator.evaluate(zOld, zNew, t, dt).tangent());
  const auto residual = [&](const VectorXd& z) -> VectorXd { return integrator.evaluate(zOld, z, t, dt).residual(); };
  expectTangentMatches(model, analytic, centralDifferences(residual, zNew, magnitude, c.relativeStep), magnitude, 1e-6);
}

INSTANTIATE_TEST_SUITE_P(BothEnforcements, RigidStepTangent,
                         ::testing::Values(TangentCase{"penalty", 1e-2, 1e-6}, TangentCase{"penalty", 0.0, 1e-7},
                                           TangentCase{"augmented_lagrangian", 1e-2, 1e-6},
                                           TangentCase{"augmented_lagrangian", 0.0, 1e-7}),
                         [](const ::testing::TestParamInfo<TangentCase>& info) {
                           return std::string(info.param.enforcement) +
                                  (info.param.offset > 0.0 ? "_away_from_old_state" : "_at_old_state");
                         });

}  // namespace
}  // namespace mpx::test
