// Every tangent against central differences of its residual: the assembled step system of each
// scheme (EEM with both discrete-gradient forms, eem4's stage system, midpoint, trapezoidal) on
// small scenes that
// together hold every scene element, in both thermal variables, and the components' rate form
// alpha dF/dz + beta dF/dzdot for arbitrary alpha, beta; and the quadratic forms of joints.
#include "models/multibody/quadratic_form.hpp"
#include "support.hpp"
#include "tangent_check.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <iterator>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace mpx {
namespace {

using test::centralDifferences;
using test::expectTangentMatches;
using test::magnitudeAt;
using test::randomIsh;
using test::schemeName;

using Eigen::MatrixXd;
using Eigen::VectorXd;

constexpr double kTime = 0.7;  // inside the rising part of every load profile below
constexpr double kTimeStep = 0.1;
constexpr double kTolerance = 1e-6;

// Stiffness curvature of the thermo-elements: only the temperature form admits one.
std::string curvature(ThermalVariable variable) {
  return variable == ThermalVariable::Temperature ? R"( stiffness_curvature="0.05")" : "";
}

// A spring pendulum in gravity under a constant load.
std::string springInGravity(ThermalVariable) {
  return R"(<gravity g="0 0 -9.81"/>
    <anchor name="pivot" position="0 0 0"/>
    <mass name="bob" mass="2" position="1 0 -0.5" velocity="0 1 0"/>
    <spring name="spring" a="pivot" b="bob" stiffness="200" rest_length="1"/>
    <force name="push" on="bob" force="0 5 0" profile="constant"/>)";
}

// Two masses joined by an isothermal Maxwell element and a dashpot, one tied to an anchor by
// another dashpot, under ramp, hat and table loads.
std::string maxwellWithDampers(ThermalVariable) {
  return R"(<anchor name="pivot" position="-1 0.2 0"/>
    <mass name="m1" mass="1" position="0 0 0" velocity="0 -0.4 0.1"/>
    <mass name="m2" mass="2" position="1.5 0 0" velocity="0.1 0.2 -0.05"/>
    <maxwell name="element" a="m1" b="m2" stiffness="1" rest_length="1" branch_stiffness="2" viscosity="1"
             viscous_elongation="0.1"/>
    <damper name="between" a="m1" b="m2" coefficient="0.5"/>
    <damper name="to_pivot" a="pivot" b="m1" coefficient="0.3"/>
    <force name="ramp" on="m1" force="0 1 0" profile="ramp" start="0" end="2"/>
    <force name="hat" on="m2" force="0.5 0 0" profile="hat" period="4"/>
    <force name="table" on="m2" force="0 0 1" profile="table" times="0 0.5 1 2" values="0 1 -0.5 2"/>)";
}

// A thermo-spring with temperature-dependent stiffness, conducting to a prescribed temperature.
std::string thermoSpringToWall(ThermalVariable variable) {
  return R"(<anchor name="pivot" position="0 0 0"/>
    <mass name="bob" mass="1" position="1.2 0 0" velocity="0 1 0"/>
    <thermo_spring name="spring" a="pivot" b="bob" stiffness="1" stiffness_slope="-0.2")" +
         curvature(variable) + R"( coupling="0.5" rest_length="1" heat_capacity="1" reference_temperature="1"
                   temperature="1"/>
    <fixed_temperature name="wall" temperature="2"/>
    <heat_link name="to_wall" a="spring" b="wall" conductivity="0.2"/>)";
}

// A thermo-Maxwell element with temperature-dependent viscosity and a thermo-spring sharing a
// mass, both conducting to each other and to a reservoir, in gravity.
std::string thermoMaxwellChain(ThermalVariable variable) {
  return R"(<gravity g="0 0 -1"/>
    <mass name="m1" mass="1" position="0 0 0" velocity="0 -0.4 0.1"/>
    <mass name="m2" mass="2" position="1.5 0 0" velocity="0.1 0.2 -0.05"/>
    <mass name="m3" mass="1" position="1.9 1.1 0.2" velocity="0 0 0.3"/>
    <thermo_maxwell name="visco" a="m1" b="m2" stiffness="1" stiffness_slope="-0.1")" +
         curvature(variable) + R"( coupling="0.5" rest_length="1" heat_capacity="1" reference_temperature="1"
                    branch_stiffness="2" viscosity="1" viscosity_activation="0.5" viscous_strain="0.05"
                    temperature="1.2"/>
    <thermo_spring name="spring" a="m2" b="m3" stiffness="2" coupling="0.3" rest_length="1" heat_capacity="2"
                   reference_temperature="1" temperature="0.9"/>
    <reservoir name="environment" heat_capacity="5" reference_temperature="1" temperature="1"/>
    <heat_link name="between" a="visco" b="spring" conductivity="0.7"/>
    <heat_link name="visco_out" a="visco" b="environment" conductivity="0.5"/>
    <heat_link name="spring_out" a="environment" b="spring" conductivity="0.3"/>)";
}

// Two rigid bodies on a revolute hinge (augmented Lagrangian) and a prismatic slider
// (penalty), with a torsional spring, a Maxwell branch, damping and friction heating a
// reservoir, and a nonlinear spring, a Maxwell branch and a damper on the slider dissipating
// without a thermal node; a third body on a spherical joint with a viscoelastic bushing.
std::string dissipativeJoints(ThermalVariable) {
  return R"(<gravity g="0 0 -9.81"/>
    <anchor name="ground" position="0 0 0"/>
    <body name="arm" mass="1" inertia="0.01 0.09 0.09" position="0.5 0 0" angular_velocity="0 0.7 0"/>
    <body name="slider" mass="0.5" inertia="0.02 0.03 0.04" position="1.2 0 0.1" velocity="0.2 0 -0.35"
          angular_velocity="0 0.7 0"/>
    <joint name="hinge" type="revolute" a="ground" b="arm" anchor="0 0 0" axis="0 1 0"/>
    <joint name="slide" type="prismatic" a="arm" b="slider" anchor="1.2 0 0.1" axis="1 0 0"
           enforcement="penalty" stiffness="1e4"/>
    <reservoir name="bearing" heat_capacity="2" reference_temperature="1" temperature="1.1"/>
    <joint_force name="hinge_losses" joint="hinge" stiffness="3" rest="0.2" damping="0.4" friction="0.1"
                 friction_velocity="0.5" branch_stiffness="2" viscosity="0.6" heat_node="bearing"/>
    <joint_force name="slide_spring" joint="slide" stiffness="20" rest="0.05" cubic_stiffness="50" damping="0.3"
                 friction="0.2" friction_velocity="0.3" branch_stiffness="8" viscosity="0.4"/>
    <body name="bob" mass="0.3" inertia="0.01 0.015 0.02" position="1.5 0 0.1" angular_velocity="0.3 -0.5 1"/>
    <joint name="ball" type="spherical" a="slider" b="bob" anchor="1.4 0 0.1"/>
    <joint_force name="bushing" joint="ball" stiffness="4" damping="0.2" branch_stiffness="1" viscosity="0.3"
                 heat_node="bearing"/>)";
}

// Every two-point element at points of two tumbling bodies and a mass, with an actuator: the
// forces reach the centre and director rows through the points' body coordinates.
std::string bodyPointElements(ThermalVariable variable) {
  return R"(<gravity g="0 0 -1"/>
    <body name="left" mass="2" inertia="0.2 0.3 0.4 0.03 -0.02 0.01" orientation="0.9 0.1 0.3 -0.2"
          velocity="0.1 0.2 -0.1" angular_velocity="1 2 3"/>
    <body name="right" mass="1.5" inertia="0.15 0.1 0.2" orientation="0.8 -0.3 0.1 0.5" position="1.2 0.1 -0.1"
          velocity="-0.2 0 0.1" angular_velocity="-2 0.5 1" enforcement="penalty" stiffness="1e4"/>
    <mass name="bob" mass="1" position="0.5 1 0" velocity="0 0 0.3"/>
    <anchor name="wall" position="-1 0 0"/>
    <spring name="spring" a="left" a_point="0.2 0.1 0.05" b="right" b_point="1 -0.05 0.1" stiffness="50"
            rest_length="0.6"/>
    <maxwell name="maxwell" a="bob" b="right" b_point="1.1 0 -0.15" stiffness="10" rest_length="1"
             branch_stiffness="20" viscosity="0.5" viscous_elongation="0.05"/>
    <damper name="damper" a="left" a_point="-0.1 0.15 0" b="right" b_point="1.3 0.2 -0.2" coefficient="0.8"/>
    <thermo_spring name="thermo" a="wall" b="left" b_point="0.1 -0.2 0.1" stiffness="1" stiffness_slope="-0.2")" +
         curvature(variable) + R"( coupling="0.5" rest_length="1" heat_capacity="1" reference_temperature="1"
                   temperature="1"/>
    <thermo_maxwell name="visco" a="left" a_point="0 0.2 -0.1" b="right" b_point="1.2 0.2 0" stiffness="1"
                    coupling="0.5" rest_length="1" heat_capacity="1" reference_temperature="1" branch_stiffness="2"
                    viscosity="1" viscosity_activation="0.5" viscous_strain="0.05" temperature="1.2"/>
    <heat_link name="between" a="visco" b="thermo" conductivity="0.7"/>
    <actuator name="push" a="right" a_point="1.2 -0.1 0.1" b="bob" force="2" profile="ramp" start="0" end="2"/>
    <torque name="twist" on="left" torque="0.3 -0.2 0.5" profile="ramp" start="0" end="2"/>)";
}

// A hinge and a slider each started beyond one of their stops (damped), the hinge's stops
// heating a reservoir, and an undamped hinge spring (which reads no velocity in any form).
std::string jointStops(ThermalVariable) {
  return R"(<gravity g="0 0 -9.81"/>
    <anchor name="ground" position="0 0 0"/>
    <body name="arm" mass="1" inertia="0.01 0.09 0.09" position="0.5 0 0" angular_velocity="0 0.7 0"/>
    <body name="slider" mass="0.5" inertia="0.02 0.03 0.04" position="1.2 0 0.1" velocity="0.2 0 -0.35"
          angular_velocity="0 0.7 0"/>
    <joint name="hinge" type="revolute" a="ground" b="arm" anchor="0 0 0" axis="0 1 0" coordinate="0.3"/>
    <joint name="slide" type="prismatic" a="arm" b="slider" anchor="1.2 0 0.1" axis="1 0 0"
           enforcement="penalty" stiffness="1e4"/>
    <reservoir name="bearing" heat_capacity="2" reference_temperature="1" temperature="1.1"/>
    <joint_force name="hinge_stops" joint="hinge" lower="-1" upper="0.25" limit_stiffness="500" limit_damping="20"
                 heat_node="bearing"/>
    <joint_force name="slide_stops" joint="slide" lower="0.02" upper="0.4" limit_stiffness="3e4"
                 limit_damping="100" damping="0.1"/>
    <joint_force name="hinge_spring" joint="hinge" stiffness="2" rest="0.1"/>)";
}

// Two tumbling links: a hinge under the augmented Lagrangian (multipliers at each eem4 stage)
// and a ball joint by penalty, in gravity.
std::string hingedLinks(ThermalVariable) {
  return R"(<constraints enforcement="augmented_lagrangian" stiffness="1e3"/>
    <gravity g="0 0 -9.81"/>
    <anchor name="ground" position="0 0 0"/>
    <body name="link1" mass="1" inertia="0.02 0.08 0.09" position="0.5 0 0" angular_velocity="0 0.6 0"/>
    <body name="link2" mass="0.7" inertia="0.03 0.05 0.06" position="1.5 0 0" velocity="0 0.5 -0.3"
          angular_velocity="0.2 0.6 1"/>
    <joint name="hinge" type="revolute" a="ground" b="link1" anchor="0 0 0" axis="0 1 0"/>
    <joint name="ball" type="spherical" a="link1" b="link2" anchor="1 0 0" enforcement="penalty" stiffness="1e4"/>)";
}

struct SceneBody {
  const char* name;
  std::string (*body)(ThermalVariable);
};

const SceneBody kScenes[] = {{"spring_in_gravity", springInGravity},
                             {"maxwell_with_dampers", maxwellWithDampers},
                             {"thermo_spring_to_wall", thermoSpringToWall},
                             {"thermo_maxwell_chain", thermoMaxwellChain},
                             {"dissipative_joints", dissipativeJoints},
                             {"body_point_elements", bodyPointElements},
                             {"hinged_links", hingedLinks},
                             {"joint_stops", jointStops}};

std::string variableName(ThermalVariable variable) {
  return variable == ThermalVariable::Temperature ? "temperature" : "entropy";
}

CompiledScene compile(const SceneBody& scene, ThermalVariable variable, DiscreteGradientForm form) {
  const std::string simulation = R"(<simulation dt="0.1" t_end="10" discrete_gradient=")" +
                                 std::string(form == DiscreteGradientForm::Gonzalez ? "gonzalez" : "partitioned") +
                                 R"("/>)";
  return loadSceneText("<metriplex>" + simulation + scene.body(variable) + "</metriplex>", scene.name, variable);
}

struct StepCase {
  const SceneBody* scene;
  ThermalVariable variable;
  DiscreteGradientForm form;
  Scheme scheme;
};

void PrintTo(const StepCase& c, std::ostream* out) { *out << c.scene->name; }

std::vector<StepCase> stepCases() {
  std::vector<StepCase> cases;
  for (const SceneBody& scene : kScenes)
    for (ThermalVariable variable : {ThermalVariable::Temperature, ThermalVariable::Entropy})
      for (DiscreteGradientForm form : {DiscreteGradientForm::Partitioned, DiscreteGradientForm::Gonzalez})
        for (Scheme scheme : {Scheme::Eem, Scheme::Eem4, Scheme::Midpoint, Scheme::Trapezoidal}) {
          // the discrete-gradient form only matters to EEM
          if (scheme != Scheme::Eem && form == DiscreteGradientForm::Gonzalez) continue;
          cases.push_back({&scene, variable, form, scheme});
        }
  return cases;
}

class StepTangent : public testing::TestWithParam<StepCase> {
 protected:
  void SetUp() override {
    const StepCase& c = GetParam();
    scene_ = compile(*c.scene, c.variable, c.form);
    integrator_.emplace(*scene_.model, c.scheme, NewtonSettings{});
    zOld_ = scene_.model->initialState();
    // the Newton unknowns: the end state, or eem4's stage values
    oldUnknowns_ = zOld_.replicate(integrator_->stageCount(), 1);
  }
  VectorXd magnitude(const VectorXd& unknowns) const {
    return unknowns.cwiseAbs() + scene_.model->dofScale().replicate(integrator_->stageCount(), 1);
  }

  // The step's tangent at the unknowns against central differences of its residual.
  void expectTangentMatchesAt(const VectorXd& unknowns, double relativeStep, double tolerance = kTolerance) {
    Integrator& integrator = *integrator_;
    const MatrixXd analytic(integrator.evaluate(zOld_, unknowns, kTime, kTimeStep).tangent());
    const auto residual = [&](const VectorXd& z) -> VectorXd {
      return integrator.evaluate(zOld_, z, kTime, kTimeStep).residual();
    };
    const VectorXd magnitude = this->magnitude(unknowns);
    expectTangentMatches(*scene_.model, analytic, centralDifferences(residual, unknowns, magnitude, relativeStep),
                         magnitude, tolerance);
  }

  CompiledScene scene_;
  std::optional<Integrator> integrator_;
  VectorXd zOld_, oldUnknowns_;
};

// A generic end point, 1e-2 relative away from zOld in every dof: every difference quotient
// of the discrete gradients is taken (increments far above kQuotientSwitch).
TEST_P(StepTangent, MatchesFiniteDifferencesAwayFromOldState) {
  expectTangentMatchesAt(oldUnknowns_ + 1e-2 * randomIsh(magnitude(oldUnknowns_), 7), 1e-6);
}

// zNew = zOld, where Newton starts every step: the quotients' midpoint limits are in use, and
// differencing steps of 1e-7 stay below kQuotientSwitch.
// At zero motion eem4's stage-gradient correction mu G a' (engine/core/stage_gradient.hpp) is
// smoothed by its floor only to about the round-off of the energy difference: the differences
// see 1e-4 of the stiffness from it (the Gauss quadrature error coefficient at dt omega ~ 1).
TEST_P(StepTangent, MatchesFiniteDifferencesAtOldState) {
  expectTangentMatchesAt(oldUnknowns_, 1e-7, GetParam().scheme == Scheme::Eem4 ? 1e-3 : kTolerance);
}

// The pattern holds only pairs a component writes: at a generic state every entry of the hinged
// links' tangent (rigid bodies, a hinge by augmented Lagrangian, a ball joint by penalty) is
// non-zero, in the step, stage and rate forms, but for a dof's own pair in each block of stages
// (the assembler's diagonal, and eem4's held multipliers, written in their own stage only). A
// pair claimed beyond a form's reach costs in every factorisation and solve (docs/performance.md,
// "Stage passes that share their work; tangent patterns of the forms' reach").
TEST(TangentPattern, HoldsOnlyPairsTheConstraintsWrite) {
  const auto hinged = std::find_if(std::begin(kScenes), std::end(kScenes),
                                   [](const SceneBody& s) { return std::string(s.name) == "hinged_links"; });
  ASSERT_NE(hinged, std::end(kScenes));
  const CompiledScene scene = compile(*hinged, ThermalVariable::Entropy, DiscreteGradientForm::Partitioned);
  for (Scheme scheme : {Scheme::Eem, Scheme::Eem4, Scheme::Midpoint}) {
    Integrator integrator(*scene.model, scheme, NewtonSettings{});
    const VectorXd zOld = scene.model->initialState();
    const VectorXd start = zOld.replicate(integrator.stageCount(), 1);
    const VectorXd magnitude = start.cwiseAbs() + scene.model->dofScale().replicate(integrator.stageCount(), 1);
    const Eigen::SparseMatrix<double>& K =
        integrator.evaluate(zOld, start + 1e-2 * randomIsh(magnitude, 7), kTime, kTimeStep).tangent();
    const int dofs = scene.model->layout().total();
    int zeros = 0;
    for (int column = 0; column < K.outerSize(); ++column)
      for (Eigen::SparseMatrix<double>::InnerIterator it(K, column); it; ++it)
        if (it.row() % dofs != column % dofs && it.value() == 0.0) ++zeros;
    EXPECT_EQ(zeros, 0) << schemeName(scheme) << ": zero entries of " << K.nonZeros();
  }
}

// An EEM step reads velocities only in the kinematic rows and the inertias' momentum rows: the
// rates of its dampers, joint forces and heat exchange are the positions' (x' - x)/dt, an
// actuator and a temperature read no velocity at all. So the step tangent of every test scene
// holds no zero entry in a velocity column; with the claims of dampers, actuators, joint forces
// and heat links as they were (every column), 3 to 678 per scene (docs/performance.md, "Velocities
// of their own: the predictor and the step's tangent pattern").
TEST(TangentPattern, StepClaimsNoVelocityItDoesNotRead) {
  for (const SceneBody& body : kScenes) {
    const CompiledScene scene = compile(body, ThermalVariable::Entropy, DiscreteGradientForm::Partitioned);
    const Layout& layout = scene.model->layout();
    Integrator integrator(*scene.model, Scheme::Eem, NewtonSettings{});
    const VectorXd zOld = scene.model->initialState();
    const VectorXd magnitude = zOld.cwiseAbs() + scene.model->dofScale();
    const Eigen::SparseMatrix<double>& K =
        integrator.evaluate(zOld, zOld + 1e-2 * randomIsh(magnitude, 7), kTime, kTimeStep).tangent();
    int zeros = 0;
    for (int column = layout.offset(Block::Velocity); column < layout.offset(Block::Thermal); ++column)
      for (Eigen::SparseMatrix<double>::InnerIterator it(K, column); it; ++it)
        zeros += it.row() != column && it.value() == 0.0;
    EXPECT_EQ(zeros, 0) << body.name << ": zero entries in velocity columns";
  }
}

INSTANTIATE_TEST_SUITE_P(AllElements, StepTangent, testing::ValuesIn(stepCases()),
                         [](const testing::TestParamInfo<StepCase>& info) {
                           const StepCase& c = info.param;
                           return std::string(c.scene->name) + "_" + variableName(c.variable) + "_" +
                                  schemeName(c.scheme) + (c.form == DiscreteGradientForm::Gonzalez ? "_gonzalez" : "");
                         });

// The rate form F(t, z, zdot) of every component, assembled densely in the model's order (heat
// links after the owners that publish their node temperatures), with its tangent
// alpha dF/dz + beta dF/dzdot.
struct DenseSystem {
  VectorXd residual;
  MatrixXd tangent;
};

DenseSystem assembleRate(const Model& model, const VectorXd& z, const VectorXd& zdot, double alpha, double beta) {
  Workspace workspace = model.makeWorkspace();
  const int n = model.layout().total();
  DenseSystem out{VectorXd::Zero(n), MatrixXd::Zero(n, n)};
  double localResidual[kMaxLocalDofs], localTangent[kMaxLocalDofs * kMaxLocalDofs];
  for (const auto& component : model.components()) {
    const std::vector<int>& dofs = component->dofs();
    LocalSystem local{static_cast<int>(dofs.size()), localResidual, localTangent};
    local.residual().setZero();
    local.tangent().setZero();
    Flows flows;
    component->rateLocal({z.data(), zdot.data(), kTime, alpha, beta}, workspace, local, flows);
    for (int i = 0; i < local.n; ++i) {
      out.residual[dofs[i]] += local.r[i];
      for (int j = 0; j < local.n; ++j) out.tangent(dofs[i], dofs[j]) += local.tangent()(i, j);
    }
  }
  return out;
}

// alpha dF/dz + beta dF/dzdot with alpha = 0.7, beta = 1.3 (no scheme's pair), z and zdot
// differenced separately, so a z-derivative scaled by beta or a zdot-derivative by alpha shows.
TEST(RateTangent, MatchesSeparateFiniteDifferencesInStateAndRate) {
  const double alpha = 0.7, beta = 1.3;
  for (const SceneBody& scene : kScenes)
    for (ThermalVariable variable : {ThermalVariable::Temperature, ThermalVariable::Entropy}) {
      SCOPED_TRACE(std::string(scene.name) + ", " + variableName(variable));
      const CompiledScene compiled = compile(scene, variable, DiscreteGradientForm::Partitioned);
      const Model& model = *compiled.model;
      const VectorXd& z0 = model.initialState();
      const VectorXd z = z0 + 1e-2 * randomIsh(magnitudeAt(model, z0), 11);
      const VectorXd magnitude = magnitudeAt(model, z);
      const VectorXd zdot = randomIsh(magnitude, 13);
      const auto inState = [&](const VectorXd& x) { return assembleRate(model, x, zdot, alpha, beta).residual; };
      const auto inRate = [&](const VectorXd& x) { return assembleRate(model, z, x, alpha, beta).residual; };
      const MatrixXd numeric = alpha * centralDifferences(inState, z, magnitude, 1e-6) +
                               beta * centralDifferences(inRate, zdot, magnitude, 1e-6);
      expectTangentMatches(model, assembleRate(model, z, zdot, alpha, beta).tangent, numeric, magnitude, kTolerance);
    }
}

// A constraint or invariant form keeps only its Hessian's nonzeros: its value, gradient and
// Hessian equal those of the dense quadratic it was built from (a symmetric H with zero rows and
// columns, as a joint condition touches few of the 24 coordinates), its support is the
// coordinates a row of H or g reaches and its values on the support are the whole gradient's,
// and the gradient and Hessian are central differences of the value and gradient (exact for a
// quadratic).
TEST(QuadraticFormTangent, MatchesTheDenseFormAndItsFiniteDifferences) {
  constexpr int n = 12;
  ConstraintMatrix H = ConstraintMatrix::Zero(n, n);
  const VectorXd entries = randomIsh(VectorXd::Ones(n * n), 17);
  for (int i = 0; i < n; i += 2)
    for (int j = 0; j <= i; j += 3) H(i, j) = H(j, i) = entries[i * n + j];
  // g zero where H's rows are (1, 5, 7 and 11), so that the support leaves those out
  ConstraintVector g = randomIsh(VectorXd::Ones(n), 19);
  for (int i = 0; i < n; ++i)
    if (H.row(i).isZero()) g[i] = 0.0;
  const double c = 0.3;
  const QuadraticForm form(H, g, c);
  const ConstraintVector q = randomIsh(VectorXd::Ones(n), 23);

  EXPECT_NEAR(form.valueAt(q), 0.5 * q.dot(H * q) + g.dot(q) + c, 1e-14);
  EXPECT_LT((form.gradientAt(q) - (H * q + g)).cwiseAbs().maxCoeff(), 1e-14);
  std::vector<int> support;
  for (int i = 0; i < n; ++i)
    if (!H.row(i).isZero() || g[i] != 0.0) support.push_back(i);
  EXPECT_EQ(form.supportCoordinates(), support);
  ASSERT_LT(support.size(), static_cast<std::size_t>(n));
  SupportValues onSupport;
  EXPECT_NEAR(form.valueAndSupportGradient(q, onSupport), 0.5 * q.dot(H * q) + g.dot(q) + c, 1e-14);
  EXPECT_LT((form.fromSupport(onSupport) - (H * q + g)).cwiseAbs().maxCoeff(), 1e-14);
  const ConstraintVector v = randomIsh(VectorXd::Ones(n), 31);
  EXPECT_NEAR(form.dotOnSupport(onSupport, v), (H * q + g).dot(v), 1e-13);
  VectorXd scattered = VectorXd::Zero(n);
  form.addOnSupport(2.0, onSupport, scattered);
  EXPECT_LT((scattered - 2.0 * (H * q + g)).cwiseAbs().maxCoeff(), 1e-14);
  MatrixXd hessian = MatrixXd::Zero(n, n);
  form.addHessian(1.0, hessian);
  EXPECT_EQ(hessian, MatrixXd(H));

  const auto gradient = [&](const VectorXd& x) { return VectorXd(form.gradientAt(x)); };
  EXPECT_LT((centralDifferences(gradient, q, VectorXd::Ones(n), 1e-4) - hessian).cwiseAbs().maxCoeff(), 1e-9);
  // the value's change along a direction, against the gradient at the midpoint (exact for a quadratic)
  const ConstraintVector d = randomIsh(VectorXd::Ones(n), 29);
  EXPECT_NEAR(form.valueAt(q + d) - form.valueAt(q - d), 2.0 * form.gradientAt(q).dot(d), 1e-12);
}

}  // namespace
}  // namespace mpx
