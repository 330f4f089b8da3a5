// The fourth-order EEM step (eem4: energy-consistent two-stage Gauss collocation, docs/theory.md
// section 13): observed order 4 against a fine run, the energy balance and entropy production at
// every step also at large steps, exact momenta, the stability of a stiff linear dissipative
// mode, the refusal of an element without a stage form, and the stage passes that share a
// component's path.
#include "support.hpp"
#include "tangent_check.hpp"

#include "engine/core/input_error.hpp"
#include "engine/linear/assembler.hpp"
#include "models/multibody/quadratic_constraint.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace mpx::test {
namespace {

struct OrderCase {
  const char* scene;
  ThermalVariable variable;
  double largestStep = 0.2;  // then halved three times
  double endTime = 2.0;
};

Eigen::VectorXd finalState(const Model& model, double dt, double endTime) {
  const History h = run(model, Scheme::Eem4, dt, endTime);
  EXPECT_FALSE(h.summary.failed) << h.summary.failure;
  return h.states.back();
}

// Final-state differences from a run at 1/16 of the smallest step, one per step in dts.
std::vector<Eigen::VectorXd> finalDifferences(const Model& model, const OrderCase& c, const std::vector<double>& dts) {
  const Eigen::VectorXd reference = finalState(model, dts.back() / 16, c.endTime);
  std::vector<Eigen::VectorXd> differences;
  for (double dt : dts) differences.push_back(finalState(model, dt, c.endTime) - reference);
  return differences;
}

// The max norms of dofs [first, first + count) of each difference.
std::vector<double> errorsOver(const std::vector<Eigen::VectorXd>& differences, Eigen::Index first,
                               Eigen::Index count) {
  std::vector<double> errors;
  for (const Eigen::VectorXd& d : differences) errors.push_back(d.segment(first, count).lpNorm<Eigen::Infinity>());
  return errors;
}

std::vector<double> halvings(double largest) { return {largest, largest / 2, largest / 4, largest / 8}; }

class Eem4Order : public ::testing::TestWithParam<OrderCase> {};

// The log-log slope of the final-state error (every dof but multipliers) against the step is
// 4 +- 0.2.
TEST_P(Eem4Order, IsFour) {
  const OrderCase c = GetParam();
  const CompiledScene scene = loadScene(scenePath(c.scene), c.variable);
  const std::vector<double> dts = halvings(c.largestStep);
  const std::vector<double> errors =
      errorsOver(finalDifferences(*scene.model, c, dts), 0, scene.model->layout().offset(Block::Multiplier));
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

// The rows of the constraint Jacobian G(q) over the position dofs, one per quadratic form.
Eigen::MatrixXd constraintJacobian(const Model& model, const Eigen::VectorXd& z) {
  const int positions = model.layout().size(Block::Position);
  std::vector<Eigen::VectorXd> rows;
  for (const auto& component : model.components()) {
    const auto* constraint = dynamic_cast<const QuadraticConstraint*>(component.get());
    if (!constraint) continue;
    const ConstraintSpec& spec = constraint->spec();
    ConstraintVector q(spec.positionDofs.size());
    for (Eigen::Index i = 0; i < q.size(); ++i) q[i] = z[spec.positionDofs[i]];
    for (const QuadraticForm& form : spec.forms) {
      const ConstraintVector local = form.gradientAt(q);
      Eigen::VectorXd row = Eigen::VectorXd::Zero(positions);
      for (Eigen::Index i = 0; i < q.size(); ++i) row[spec.positionDofs[i]] += local[i];
      rows.push_back(row);
    }
  }
  Eigen::MatrixXd jacobian(rows.size(), positions);
  for (std::size_t i = 0; i < rows.size(); ++i) jacobian.row(i) = rows[i].transpose();
  return jacobian;
}

// The mass matrix: the derivative of the momentum rows' rate form with respect to vdot.
Eigen::MatrixXd massMatrix(const Model& model) {
  const Eigen::VectorXd z = model.initialState(), zdot = Eigen::VectorXd::Zero(z.size());
  Assembler assembler(model, Component::LocalForm::Rate);
  Workspace ws = model.makeWorkspace();
  assembler.clear();
  assembler.addRate(model, ws, {z.data(), zdot.data(), 0.0, 0.0, 1.0}, 1.0);
  const int positions = model.layout().size(Block::Position);
  return Eigen::MatrixXd(assembler.tangent()).block(positions, positions, positions, positions);
}

// The velocity of state z split M-orthogonally into its part tangent to the constraints and
// the normal rest M^-1 G^T (G M^-1 G^T)^-1 G v.
std::pair<Eigen::VectorXd, Eigen::VectorXd> splitVelocity(const Model& model, const Eigen::MatrixXd& mass,
                                                          const Eigen::VectorXd& z) {
  const int positions = model.layout().size(Block::Position);
  const Eigen::MatrixXd g = constraintJacobian(model, z), inverseMass = mass.inverse();
  const Eigen::VectorXd v = z.segment(positions, positions);
  const Eigen::VectorXd normal =
      inverseMass * g.transpose() * (g * inverseMass * g.transpose()).completeOrthogonalDecomposition().solve(g * v);
  return {v - normal, normal};
}

// Under constraints (the double pendulum, augmented Lagrangian) positions and the velocity's
// part tangent to the constraints converge at fourth order or faster over these steps. The
// end-point velocity also has a part normal to the constraints (in the mass metric) of size
// O(dt^2), which the velocity polynomial's end value carries and the next step does not
// amplify (docs/theory.md section 13.7): it converges at second order.
TEST(Eem4OrderUnderConstraints, PositionsAndTangentVelocitiesFour) {
  const OrderCase c{"double_pendulum.xml", ThermalVariable::Temperature, 0.04, 0.5};
  const CompiledScene scene = loadScene(scenePath(c.scene));
  const Model& model = *scene.model;
  const std::vector<double> dts = halvings(c.largestStep);
  const Eigen::VectorXd reference = finalState(model, dts.back() / 16, c.endTime);
  const Eigen::MatrixXd mass = massMatrix(model);
  const Eigen::VectorXd referenceTangent = splitVelocity(model, mass, reference).first;
  const int positions = model.layout().size(Block::Position);
  std::vector<double> positionErrors, tangentErrors, normalParts;
  for (double dt : dts) {
    const Eigen::VectorXd z = finalState(model, dt, c.endTime);
    const auto [tangent, normal] = splitVelocity(model, mass, z);
    positionErrors.push_back((z - reference).head(positions).lpNorm<Eigen::Infinity>());
    tangentErrors.push_back((tangent - referenceTangent).lpNorm<Eigen::Infinity>());
    normalParts.push_back(normal.lpNorm<Eigen::Infinity>());
  }
  const double positionOrder = logLogSlope(dts, positionErrors), tangentOrder = logLogSlope(dts, tangentErrors),
               normalOrder = logLogSlope(dts, normalParts);
  std::printf("eem4 on %s by dt from %g: position errors", c.scene, c.largestStep);
  for (double e : positionErrors) std::printf(" %.3e", e);
  std::printf(" (order %.3f); tangent velocity errors", positionOrder);
  for (double e : tangentErrors) std::printf(" %.3e", e);
  std::printf(" (order %.3f); normal velocity", tangentOrder);
  for (double e : normalParts) std::printf(" %.3e", e);
  std::printf(" (order %.3f)\n", normalOrder);
  EXPECT_GT(positionOrder, 3.8);
  EXPECT_GT(tangentOrder, 3.8);
  EXPECT_NEAR(normalOrder, 2.0, 0.2);
}

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

INSTANTIATE_TEST_SUITE_P(
    LargeSteps, Eem4Balances,
    ::testing::Values(BalanceCase{"two_thermo_springs.xml", 1.0, 100.0, 1e-14, kEntropyRoundOff},
                      BalanceCase{"thermo_visco_elastic.xml", 0.5, 100.0, 1e-9, 1e-10},
                      BalanceCase{"isothermal_maxwell.xml", 0.5, 100.0, 1e-9, kEntropyRoundOff},
                      BalanceCase{"heated_thermo_spring.xml", 0.5, 50.0, 1e-14, kEntropyRoundOff},
                      BalanceCase{"stiff_thermo_chain.xml", 0.25, 10.0, 1e-11, kEntropyRoundOff},
                      BalanceCase{"double_pendulum.xml", 0.05, 5.0, 1e-10, kEntropyRoundOff},
                      BalanceCase{"double_pendulum_penalty.xml", 0.01, 2.0, 1e-10, kEntropyRoundOff},
                      BalanceCase{"four_bar_revolute.xml", 0.02, 1.0, 1e-11, kEntropyRoundOff},
                      BalanceCase{"damped_double_pendulum.xml", 0.05, 5.0, 1e-10, kEntropyRoundOff},
                      BalanceCase{"heavy_top.xml", 0.01, 1.0, 1e-11, kEntropyRoundOff}));

// Augmented Lagrangian: the constraints hold at every step's end to Newton's tolerance (the
// multipliers' first-stage rows ask Phi(q_end) = 0), also at a large step, without drift.
TEST(Eem4Constraints, HoldAtTheStepEnds) {
  const CompiledScene scene = loadScene(scenePath("double_pendulum.xml"));
  const History h = run(*scene.model, Scheme::Eem4, 0.05, 5.0);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  double worst = 0.0;
  for (const Eigen::VectorXd& z : h.states) {
    Measures m;
    scene.model->measure(z, m);
    worst = std::max(worst, m.constraintViolation);
  }
  std::printf("eem4 on double_pendulum.xml at dt 0.05: largest |Phi| at a step end %.2e\n", worst);
  EXPECT_LT(worst, 1e-10);
}

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

// Rigid bodies held by director rigidity and joints (augmented Lagrangian, stiffness 1e6): the
// multipliers' forces take grad Phi on the stages' line, where its moment vanishes, so the free
// chain keeps its angular momentum about the origin, and the spinning heavy top (150 rad/s) its
// angular momentum about the vertical, to round-off. With grad Phi on the step's path they leaked
// 6e-7 of the chain's and 10 % of the top's over its 2 s, at O(dt^4).
TEST(Eem4Momenta, AreExactForRigidBodiesUnderConstraints) {
  struct Case {
    const char* scene;
    double dt, tEnd;
    bool aboutVerticalOnly;
  };
  for (const Case& c : {Case{"free_floating_chain.xml", 0.02, 2.0, false}, Case{"heavy_top.xml", 0.002, 0.4, true}}) {
    const CompiledScene scene = loadScene(scenePath(c.scene));
    const History h = run(*scene.model, Scheme::Eem4, c.dt, c.tEnd);
    ASSERT_FALSE(h.summary.failed) << c.scene << ": " << h.summary.failure;
    double drift = 0.0;
    for (const Vec3& angular : h.angularMomentum) {
      const Vec3 change = angular - h.angularMomentum[0];
      drift =
          std::max(drift, (c.aboutVerticalOnly ? std::abs(change.z()) : change.norm()) / h.angularMomentum[0].norm());
    }
    std::printf("eem4 on %s at dt %g: largest relative change of the angular momentum %.2e\n", c.scene, c.dt, drift);
    EXPECT_LT(drift, 1e-12) << c.scene;
  }
}

// A closed loop floating free (a four-bar whose ground is a spinning body): three of the last
// joint's conditions are implied and hold no multiplier, and their penalty forces take the same
// line as the others' (with the path's, the angular momentum changed by 1.6e-8 at stiffness 1e8).
TEST(Eem4Momenta, AreExactForAFreeLoopWithImpliedConditions) {
  const CompiledScene scene = loadSceneText(R"(<metriplex name="free_four_bar">
    <simulation dt="0.01" t_end="2" integrator="eem4"/>
    <constraints enforcement="augmented_lagrangian" stiffness="1e8"/>
    <body name="base" mass="2" inertia="0.000833 0.667 0.667" position="1 0 0" velocity="0 3 -0.5"
          angular_velocity="1 0.5 3"/>
    <body name="crank" mass="0.5" inertia="0.000208333 0.0105208 0.0105208" position="0 0.25 0"
          orientation="0.70710678118654752 0 0 0.70710678118654752" velocity="-0.75 0 0.25" angular_velocity="1 0.5 3"/>
    <body name="coupler" mass="2" inertia="0.000833333 0.667083 0.667083" position="0.872260419102717 0.9890416764108683 0"
          orientation="0.96753822123539829 0 0 0.25272473256221179"
          velocity="-2.967125029232605 2.6167812573081513 0.5529114668595098" angular_velocity="1 0.5 3"/>
    <body name="rocker" mass="1.5" inertia="0.000625 0.2815625 0.2815625" position="1.872260419102717 0.7390416764108683 0"
          orientation="0.64408095717992729 0 0 0.76495733253442879"
          velocity="-2.217125029232605 5.616781257308151 -0.19708853314049024" angular_velocity="1 0.5 3"/>
    <joint name="O1" type="revolute" a="base" b="crank" anchor="0 0 0" axis="0 0 1"/>
    <joint name="A" type="revolute" a="crank" b="coupler" anchor="0 0.5 0" axis="0 0 1"/>
    <joint name="B" type="revolute" a="coupler" b="rocker" anchor="1.744520838205434 1.4780833528217365 0" axis="0 0 1"/>
    <joint name="O2" type="revolute" a="base" b="rocker" anchor="2 0 0" axis="0 0 1"/>
  </metriplex>)",
                                            "free_four_bar");
  ASSERT_FALSE(scene.redundantConditions.empty()) << "the loop's implied conditions";
  const History h = run(*scene.model, Scheme::Eem4, 0.01, 2.0);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  double drift = 0.0;
  for (const Vec3& angular : h.angularMomentum)
    drift = std::max(drift, (angular - h.angularMomentum[0]).norm() / h.angularMomentum[0].norm());
  std::printf("eem4 on a free four-bar: largest relative change of the angular momentum %.2e\n", drift);
  EXPECT_LT(drift, 1e-12);
}

// A stiff link in almost rigid motion (the flexible pendulum): C' is tiny at every point, and a
// solid's stage gradient takes the whole quadrature defect only because its energy change comes
// from the change of F (round-off in proportion to the motion, so a floor of 1e-14 suffices). With
// W(C_end) - W(C_0) and the lumped elements' floor 1e-10 the balance drifted to 8.3e-6 by t = 0.5.
TEST(Eem4Balances, HoldForAStiffLinkInAlmostRigidMotion) {
  const CompiledScene scene = loadScene(scenePath("flexible_pendulum.xml"));
  const History h = run(*scene.model, Scheme::Eem4, scene.settings.dt, 0.5);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  std::printf("eem4 on flexible_pendulum.xml to t = 0.5: largest relative balance error %.2e\n",
              h.summary.maxEnergyBalanceError);
  EXPECT_LT(h.summary.maxEnergyBalanceError, 1e-8);
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

// Every element of the engine has a stage form; one that had none would be refused up front
// rather than integrated with a form that keeps nothing.
class WithoutStageForm final : public Component {
 public:
  WithoutStageForm() : Component("untested", {0}) {}
  void measure(const double*, Measures&) const override {}
  void eemLocal(const StepArgs&, Workspace&, LocalSystem&, Flows&) const override {}
  void rateLocal(const RateArgs&, Workspace&, LocalSystem&, Flows&) const override {}
};

TEST(Eem4Scope, RefusesAnElementWithoutAStageForm) {
  std::vector<std::unique_ptr<Component>> components;
  components.push_back(std::make_unique<WithoutStageForm>());
  std::array<int, kBlockCount> sizes{};
  sizes[static_cast<int>(Block::Position)] = 1;
  const Model model(Layout(sizes), ThermalVariable::Temperature, std::move(components), {}, Eigen::VectorXd::Zero(1),
                    Eigen::VectorXd::Ones(1));
  try {
    checkMethodSupports(*methodByName("eem4"), model, "scene.xml");
    FAIL() << "eem4 accepted an element without a stage form";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("has no fourth-order form for element 'untested'"), std::string::npos)
        << error.what();
  }
  for (const char* scene : {"lblock_thermoelastic.xml", "lblock_thermal_dirichlet.xml"})
    EXPECT_NO_THROW(checkMethodSupports(*methodByName("eem4"), *loadScene(scenePath(scene)).model, scene));
}

// An eem4 evaluation passes over the components once per pair of stages (once per stage for a
// residual alone), and after its first pass a component takes its stage path and its law's jets
// from its scratch in the workspace (StageArgs::samePath). The assembled residual and tangent
// are those of passes that compute everything afresh (a workspace without scratch), bit for bit:
// at two states in turn, each with and without the tangent, so that a path kept from an earlier
// evaluation would show.
TEST(Eem4StageScratch, SharedPassesGiveWhatFreshPassesGive) {
  const CollocationRule rule = gaussCollocation(2);
  for (const char* name : {"two_thermo_springs.xml", "thermo_visco_elastic.xml", "damped_double_pendulum.xml"}) {
    SCOPED_TRACE(name);
    const CompiledScene scene = loadScene(scenePath(name));
    const Model& model = *scene.model;
    const Eigen::VectorXd zOld = model.initialState(), magnitude = magnitudeAt(model, zOld);
    Workspace kept = model.makeWorkspace(), fresh = model.makeWorkspace();
    fresh.stageScratch.clear();
    Assembler sharing(model, Component::LocalForm::Stages, 2), afresh(model, Component::LocalForm::Stages, 2);
    for (unsigned seed : {3u, 5u}) {
      Eigen::VectorXd values[2], rates[2];
      for (int l = 0; l < 2; ++l) {
        values[l] = zOld + 1e-2 * randomIsh(magnitude, seed + 10 * l);
        rates[l] = randomIsh(magnitude, seed + 10 * l + 1);
      }
      const Eigen::VectorXd zEnd = zOld + 1e-2 * randomIsh(magnitude, seed + 100);
      const double* state[2] = {values[0].data(), values[1].data()};
      const double* rate[2] = {rates[0].data(), rates[1].data()};
      for (bool tangent : {true, false}) {
        const StageArgs args{&rule, zOld.data(), zEnd.data(), state, rate, 0.3, 0.1, 0, 0, tangent};
        sharing.clear(tangent);
        sharing.addStages(model, kept, args);
        afresh.clear(tangent);
        afresh.addStages(model, fresh, args);
        EXPECT_TRUE(sharing.residual() == afresh.residual()) << "seed " << seed << ", tangent " << tangent;
        if (tangent) {
          EXPECT_TRUE(Eigen::MatrixXd(sharing.tangent()) == Eigen::MatrixXd(afresh.tangent())) << "seed " << seed;
        }
      }
    }
  }
}

}  // namespace
}  // namespace mpx::test
