// Thermoelastic and thermo-viscoelastic solids (docs/theory.md section 9): the logarithmic
// mean on both sides of its series switch, the step and rate tangents of thermal cells and
// thermal boundaries against central differences, a purely mechanical solid without thermal
// dofs, the conduction bar against its Fourier series (order 2 in space and time), the
// isolated thermoelastic L-block (E, L, J exact after the load, S never decreasing, at small
// and large steps), in the entropy form too and against the temperature form, the viscous
// production against the isothermal dissipation, the L-block with Dirichlet temperatures (energy and entropy balances
// with boundary heat and entropy at every step), EEM converging to IDA's tight solution, and bad input.
#include "support.hpp"
#include "tangent_check.hpp"
#include "thermal_solid_checks.hpp"

#include "engine/core/discrete_gradient.hpp"
#include "engine/core/input_error.hpp"
#include "models/fe/heat_conduction.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace mpx::test {
namespace {

// ---------------------------------------------------------------------------------------------
// 1. The logarithmic mean: exact directionality c (b - a) = L c ln(b/a), its derivative, and
// continuity across the switch to the series at |b/a - 1| = 1e-3.
TEST(LogarithmicMean, IsDirectionalAndContinuousAcrossTheSeriesSwitch) {
  const double a = 300.0;
  for (double u : {0.3, -0.2, 2e-3, 1.0001e-3, 0.9999e-3, -0.5e-3, 1e-4, 1e-6, 0.0}) {
    const double b = a * (1.0 + u);
    const LogarithmicMean mean = logarithmicMean(a, b);
    // directionality and the exact mean, against long double where ln(b/a) is accurate (both
    // sides of the series switch at |u| = 1e-3)
    if (std::abs(u) >= 1e-4) {
      const long double logRatio = std::log(static_cast<long double>(b) / a), difference = b - a;
      EXPECT_NEAR(static_cast<double>(mean.value * logRatio - difference), 0.0, 1e-13 * std::abs(b - a)) << u;
      EXPECT_NEAR(mean.value, static_cast<double>(difference / logRatio), 1e-13 * a) << u;
    }
    // everywhere between the geometric and the arithmetic mean
    EXPECT_GE(mean.value, std::sqrt(a * b) - 1e-13 * a) << u;
    EXPECT_LE(mean.value, 0.5 * (a + b) + 1e-13 * a) << u;
    const double h = 1e-6 * a;
    const double numeric = (logarithmicMean(a, b + h).value - logarithmicMean(a, b - h).value) / (2 * h);
    EXPECT_NEAR(mean.derivative, numeric, 1e-6) << u;
  }
}

// Second-order consistency: the discrete temperature of a step departs from the midpoint
// temperature by -(b - a)^2 / (12 a) + ..., so halving the jump divides the gap by 4, on either
// side of the series switch.
TEST(LogarithmicMean, IsASecondOrderApproximationOfTheMidpointTemperature) {
  const double a = 300.0;
  for (double u : {0.2, 0.02, 4e-3, 5e-4}) {
    const auto gap = [&](double jump) { return logarithmicMean(a, a * (1 + jump)).value - a * (1 + 0.5 * jump); };
    EXPECT_NEAR(gap(u) / gap(0.5 * u), 4.0, 0.1 + u) << u;
    EXPECT_NEAR(gap(u), -a * u * u / 12.0, 0.3 * a * u * u * (u + 1e-3)) << u;
  }
}

// ---------------------------------------------------------------------------------------------
// 2. Tangents of thermal cells, with flux and convection on a face, and a Dirichlet face.
struct ThermalCellCase {
  const char* name;
  const char* solid;  // extra attributes of the <solid>
  const char* extra;  // further elements
  Scheme scheme;
  double perturbation = 3e-2;            // of the moved state, relative to the dofs' magnitudes
  const char* variable = "temperature";  // what the nodal thermal dofs hold
  const char* expansion = "1e-3";        // beta (0: heat and motion meet only through a branch)
};

std::string caseName(const ThermalCellCase& c) {
  return std::string(c.name) + "_" + schemeName(c.scheme) + (c.variable[0] == 'e' ? "_entropy" : "");
}

void PrintTo(const ThermalCellCase& c, std::ostream* out) { *out << caseName(c); }

std::string thermalCell(const ThermalCellCase& c) {
  return std::string(R"(<metriplex name="thermal_cell"><simulation dt="0.1" t_end="10" thermal_variable=")") +
         c.variable + R"("/>
    <solid name="cell" young="1000" poisson="0.3" density="10" velocity="0.1 -0.2 0.3"
           angular_velocity="0.5 0.2 -0.4" heat_capacity="100" conductivity="40" expansion=")" +
         c.expansion + R"(" reference_temperature="300" temperature="310" )" + c.solid + "/>" + c.extra +
         "</metriplex>";
}

class ThermalCellTangent : public ::testing::TestWithParam<ThermalCellCase> {};

TEST_P(ThermalCellTangent, MatchesFiniteDifferences) {
  const CompiledScene scene = loadSceneText(thermalCell(GetParam()), scenePath("thermal_cell.xml"));
  const Model& model = *scene.model;
  Integrator integrator(model, GetParam().scheme, NewtonSettings{});
  const VectorXd zOld =
      model.initialState() + GetParam().perturbation * randomIsh(magnitudeAt(model, model.initialState()), 3);
  // the Newton unknowns (the end state, or eem4's stage values) a generic step away from zOld
  const int stages = integrator.stageCount();
  const VectorXd unknowns =
      zOld.replicate(stages, 1) + 1e-2 * randomIsh(magnitudeAt(model, zOld).replicate(stages, 1), 5);
  const double t = 0.7, dt = 0.1;
  const MatrixXd analytic(integrator.evaluate(zOld, unknowns, t, dt).tangent());
  const auto residual = [&](const VectorXd& z) -> VectorXd { return integrator.evaluate(zOld, z, t, dt).residual(); };
  const VectorXd magnitude = unknowns.cwiseAbs() + model.dofScale().replicate(stages, 1);
  expectTangentMatches(model, analytic, centralDifferences(residual, unknowns, magnitude, 1e-6), magnitude, 1e-6);
}

std::vector<ThermalCellCase> thermalCellCases() {
  const std::string fluxes = R"(<heat_flux name="q" solid="cell" surface="x1" flux="50" profile="ramp" end="2"/>
         <convection name="h" solid="cell" surface="z0" coefficient="20" ambient="280"/>)";
  static const std::string boundaries =
      fluxes + R"(<prescribed_temperature solid="cell" surface="x0" temperature="305"/>)";
  static const std::string entropyBoundaries = fluxes;  // the entropy form takes no prescribed temperature
  std::vector<ThermalCellCase> cases;
  for (const char* variable : {"temperature", "entropy"})
    for (Scheme scheme : {Scheme::Eem, Scheme::Midpoint, Scheme::Trapezoidal, Scheme::Eem4}) {
      const bool entropy = variable[0] == 'e';
      cases.push_back({"hex8", R"(mesh="box" cells="1 1 1")", "", scheme, 3e-2, variable});
      cases.push_back({"hex8_boundaries", R"(mesh="box" cells="1 1 1")",
                       entropy ? entropyBoundaries.c_str() : boundaries.c_str(), scheme, 3e-2, variable});
      cases.push_back({"hex8_linked", R"(mesh="box" cells="1 1 1")",
                       R"(<reservoir name="r" heat_capacity="50" temperature="290"/>
                        <surface_heat_link name="l" solid="cell" surface="x1" node="r" coefficient="30"/>
                        <fixed_temperature name="w" temperature="320"/>
                        <surface_heat_link name="lw" solid="cell" surface="y0" node="w" coefficient="10"/>
                        <mass name="m1" mass="1" position="3 0 0" velocity="0.1 0 0"/>
                        <mass name="m2" mass="1" position="4 0.2 0" velocity="0 0.2 0"/>
                        <thermo_spring name="ts" a="m1" b="m2" stiffness="10" coupling="0.5" rest_length="1"
                                       heat_capacity="5" reference_temperature="300" temperature="310"/>
                        <surface_heat_link name="lt" solid="cell" surface="z1" node="ts" coefficient="5"/>)",
                       scheme, 3e-2, variable});
      cases.push_back(
          {"hex8_viscous",
           R"(mesh="box" cells="1 1 1" branch_lambda="200" branch_mu="50" viscosity="100" viscosity_activation="0.02")",
           "", scheme, 3e-2, variable});
      // without expansion (and activation) the pattern leaves the thermo-mechanical pairs out
      cases.push_back({"hex8_unexpanding", R"(mesh="box" cells="1 1 1")", "", scheme, 3e-2, variable, "0"});
      cases.push_back({"hex8_viscous_unexpanding",
                       R"(mesh="box" cells="1 1 1" branch_lambda="200" branch_mu="50" viscosity="100")", "", scheme,
                       3e-2, variable, "0"});
      cases.push_back(
          {"hex8_activated_unexpanding",
           R"(mesh="box" cells="1 1 1" branch_lambda="200" branch_mu="50" viscosity="100" viscosity_activation="0.02")",
           "", scheme, 3e-2, variable, "0"});
    }
  // the bar's tetrahedra are 0.5 across in a body 4 long: a smaller perturbation keeps them uninverted
  cases.push_back(
      {"tet4_viscous", R"(mesh="meshes/bar_tets.msh" branch_mu="50" viscosity="100")", "", Scheme::Eem, 5e-3});
  return cases;
}

INSTANTIATE_TEST_SUITE_P(EveryCell, ThermalCellTangent, ::testing::ValuesIn(thermalCellCases()),
                         [](const ::testing::TestParamInfo<ThermalCellCase>& info) { return caseName(info.param); });

// ---------------------------------------------------------------------------------------------
// 2b. On a flat tetrahedron with obtuse dihedral angles, where the plain Galerkin conduction
// matrix has positive off-diagonal entries, the entropy-weak rows still give zero net energy and
// the production sum_q w k0 |Grad theta|^2 / theta^2 >= 0 for any temperatures; Galerkin's
// sum_a (K theta)_a / theta_a does go negative there.
TEST(HeatConduction, ProducesEntropyOnAnObtuseTetrahedronWherePlainGalerkinDoesNot) {
  const std::vector<Vec3> nodes = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.33, 0.33, 0.02}};
  const std::vector<CellPoint> points = cellQuadrature(CellType::Tet4, nodes, Integrand::Stiffness);
  const double k0 = 3.0;
  const HeatConduction conduction("tet", {0, 1, 2, 3}, NodalThermalVariable(), points, k0);
  const Eigen::Vector4d theta(300.0, 400.0, 300.0, 330.0), thetaNew = theta;
  std::vector<double> r(4), k(16);
  LocalSystem local{4, r.data(), k.data()};
  Workspace ws;
  Flows flows;
  conduction.eemLocal({theta.data(), thetaNew.data(), 0.0, 0.1}, ws, local, flows);
  // the nodal temperatures the rows are weighted with, and the point's gradient
  Eigen::Vector4d T;
  for (int a = 0; a < 4; ++a) T[a] = logarithmicMean(theta[a], thetaNew[a]).value;
  const Vec3 gradient = points[0].gradients.topRows<4>().transpose() * T;
  const double pointTemperature = points[0].values.head<4>().dot(T);
  double energy = 0.0, production = 0.0;
  for (int a = 0; a < 4; ++a) {
    energy += r[a];
    production -= r[a] / T[a];
  }
  EXPECT_NEAR(energy, 0.0, 1e-12 * std::abs(r[0]));
  EXPECT_NEAR(production, points[0].weight * k0 * gradient.squaredNorm() / std::pow(pointTemperature, 2),
              1e-12 * production);
  // plain Galerkin: R = K T with K_ab = w k0 Grad N_a . Grad N_b
  const Eigen::Matrix4d galerkin =
      points[0].weight * k0 * points[0].gradients.topRows<4>() * points[0].gradients.topRows<4>().transpose();
  EXPECT_GT(galerkin(1, 2), 0.0);  // not an M-matrix
  const Eigen::Vector4d rows = galerkin * T;
  const double galerkinProduction = -(rows.array() / T.array()).sum();
  std::printf("entropy-weak production %.3e, plain Galerkin %.3e\n", production, galerkinProduction);
  EXPECT_GT(production, 0.0);
  EXPECT_LT(galerkinProduction, 0.0);
}

// ---------------------------------------------------------------------------------------------
// 3. Only a solid with a thermal material owns temperatures.
TEST(ThermalSolid, AMechanicalSolidHasNoThermalDofs) {
  const char* mechanical = R"(<metriplex name="m"><simulation dt="0.1" t_end="1"/>
    <solid name="s" mesh="box" cells="2 1 1" young="1000" poisson="0.3" density="10"/></metriplex>)";
  const char* thermal = R"(<metriplex name="t"><simulation dt="0.1" t_end="1"/>
    <solid name="s" mesh="box" cells="2 1 1" young="1000" poisson="0.3" density="10" heat_capacity="1"/></metriplex>)";
  EXPECT_EQ(loadSceneText(mechanical, "m.xml").model->layout().size(Block::Thermal), 0);
  EXPECT_EQ(loadSceneText(thermal, "t.xml").model->layout().size(Block::Thermal), 12);
}

// ---------------------------------------------------------------------------------------------
// 4. Pure conduction: a bar of length 1 at rest (beta = 0), kappa = k0 = 1, initially at 350 K with
// both ends held at 300 K. theta = 300 + sum_{n odd} 200/(n pi) sin(n pi x) exp(-n^2 pi^2 t).
double barTemperature(double x, double t) {
  double sum = 300.0;
  for (int n = 1; n < 400; n += 2)
    sum += 200.0 / (n * M_PI) * std::sin(n * M_PI * x) * std::exp(-n * n * M_PI * M_PI * t);
  return sum;
}

std::string conductionBar(int cells) {
  return R"(<metriplex name="bar"><simulation dt="0.01" t_end="0.1"/>
    <solid name="bar" mesh="box" size="1 0.1 0.1" cells=")" +
         std::to_string(cells) + R"( 1 1" young="1000" poisson="0.3" density="1" heat_capacity="1"
           conductivity="1" reference_temperature="300" temperature="350"/>
    <prescribed_temperature solid="bar" surface="x0" temperature="300"/>
    <prescribed_temperature solid="bar" surface="x1" temperature="300"/></metriplex>)";
}

// L2 norm of the nodal error at t_end over the bar's nodes (lumped: length h per node)
double barError(int cells, double dt, double tEnd) {
  const CompiledScene scene = loadSceneText(conductionBar(cells), "bar.xml");
  const History h = run(*scene.model, Scheme::Eem, dt, tEnd);
  const SolidPlacement& bar = scene.solids.front();
  double sum = 0.0;
  for (std::size_t n = 0; n < bar.mesh->nodes.size(); ++n) {
    const double x = bar.mesh->nodes[n].x();
    const double error = bar.nodeTemperature(h.states.back().data(), static_cast<int>(n)) - barTemperature(x, tEnd);
    sum += error * error / (4.0 * cells);  // four nodes per x-station
  }
  return std::sqrt(sum);
}

TEST(ConductionBar, ConvergesAtOrderTwoInSpaceAgainstTheFourierSeries) {
  std::vector<double> sizes, errors;
  for (int cells : {4, 8, 16}) {
    sizes.push_back(1.0 / cells);
    errors.push_back(barError(cells, 2.5e-4, 0.05));
    std::printf("conduction bar, %d cells: L2 error %.3e\n", cells, errors.back());
  }
  EXPECT_NEAR(logLogSlope(sizes, errors), 2.0, 0.2);
}

TEST(ConductionBar, ConvergesAtOrderTwoInTime) {
  const CompiledScene scene = loadSceneText(conductionBar(8), "bar.xml");
  const VectorXd reference = run(*scene.model, Scheme::Eem, 0.05 / 256, 0.05).states.back();
  std::vector<double> steps, errors;
  for (double dt : {0.05 / 8, 0.05 / 16, 0.05 / 32}) {
    steps.push_back(dt);
    errors.push_back((run(*scene.model, Scheme::Eem, dt, 0.05).states.back() - reference).norm());
  }
  EXPECT_NEAR(logLogSlope(steps, errors), 2.0, 0.2);
}

// eem4 at a stiff step (dt 0.05, about 40 times the fastest conduction mode's time): A-stable
// with 0 < R(z) < 1 on the negative real axis (docs/theory.md section 13.4), every mode of the
// hot bar decays without changing sign; the uniformly hot start gives every mode a positive
// share of the mean temperature, which therefore falls at every step and stays above the
// walls' 300 K. Both balances hold at every step.
TEST(ConductionBar, Eem4CoolsMonotonicallyAtAStiffStep) {
  const CompiledScene scene = loadSceneText(conductionBar(8), "bar.xml");
  const History h = run(*scene.model, Scheme::Eem4, 0.05, 0.5);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  expectStepBalances(h, "conduction bar, eem4 dt 0.05");
  const SolidPlacement& bar = scene.solids.front();
  auto meanTemperature = [&](const VectorXd& z) {
    double sum = 0.0;
    for (std::size_t n = 0; n < bar.thermalDofs.size(); ++n) sum += bar.nodeTemperature(z.data(), static_cast<int>(n));
    return sum / static_cast<double>(bar.thermalDofs.size());
  };
  for (std::size_t n = 1; n < h.states.size(); ++n) {
    const double before = meanTemperature(h.states[n - 1]), after = meanTemperature(h.states[n]);
    std::printf("t = %.2f: mean temperature %.6f\n", h.time[n], after);
    EXPECT_LT(after, before) << "step " << n;
    EXPECT_GT(after, 300.0) << "step " << n;
  }
}

// ---------------------------------------------------------------------------------------------
// 5. Thermoelastic L-block, isolated: E, L, J exact after the load (t >= 2), S never decreasing.
TEST(ThermoelasticLBlock, EemKeepsEnergyMomentaAndEntropyAtSmallAndLargeSteps) {
  const CompiledScene scene = loadScene(scenePath("lblock_thermoelastic.xml"));
  expectIsolatedBalances(run(*scene.model, Scheme::Eem, 0.025, 15.0), "EEM dt 0.025");
  expectIsolatedBalances(run(*scene.model, Scheme::Eem, 0.2, 15.0), "EEM dt 0.2");
  // the midpoint rule keeps the momenta but not the energy: reported, not asserted
  const History midpoint = run(*scene.model, Scheme::Midpoint, 0.2, 15.0);
  const std::size_t free = firstIndexAfter(midpoint, 2.0);
  std::printf("midpoint dt 0.2: energy change after the load %.3e of %.3e (%s)\n",
              midpoint.energy.back() - midpoint.energy[free], midpoint.energy[free],
              midpoint.summary.failed ? midpoint.summary.failure.c_str() : "ran to the end");
}

// 5b. The entropy form (nodal dofs s_a = kappa ln(theta_a/theta_R)) keeps the same balances, and
// since its discrete temperature is again the logarithmic mean (docs/theory.md section 9.7) it
// solves the same discrete system as the temperature form: the two agree to Newton's tolerance,
// far inside the O(dt^2) time error (measured here as the change when dt is halved).
// The midpoint rule, whose midpoint temperature theta(s_m) differs from theta_m at O(dt^2), does
// depend on the form: its two solutions approach each other at order 2.
struct FormSolution {
  VectorXd positions, temperatures;
};

FormSolution finalSolution(const CompiledScene& scene, const History& h) {
  const SolidPlacement& block = scene.solids.front();
  const Layout& layout = scene.model->layout();
  FormSolution s{h.states.back().segment(layout.offset(Block::Position), layout.size(Block::Position)),
                 VectorXd(block.thermalDofs.size())};
  for (Eigen::Index n = 0; n < s.temperatures.size(); ++n)
    s.temperatures[n] = block.nodeTemperature(h.states.back().data(), static_cast<int>(n));
  return s;
}

double formDifference(const FormSolution& a, const FormSolution& b) {
  return std::max((a.positions - b.positions).cwiseAbs().maxCoeff() / 10.0,  // block size 10
                  (a.temperatures - b.temperatures).cwiseAbs().maxCoeff() / 300.0);
}

TEST(ThermoelasticLBlock, EntropyFormKeepsTheBalancesAndAgreesWithTheTemperatureForm) {
  const CompiledScene temperature = loadScene(scenePath("lblock_thermoelastic.xml"));
  const CompiledScene entropy = loadScene(scenePath("lblock_thermoelastic.xml"), ThermalVariable::Entropy);
  ASSERT_EQ(entropy.model->thermalVariable(), ThermalVariable::Entropy);
  expectIsolatedBalances(run(*entropy.model, Scheme::Eem, 0.2, 15.0), "entropy form EEM dt 0.2");

  const double tEnd = 3.0;
  const auto solve = [&](const CompiledScene& scene, Scheme scheme, double dt) {
    const History h = run(*scene.model, scheme, dt, tEnd);
    EXPECT_FALSE(h.summary.failed) << h.summary.failure;
    return finalSolution(scene, h);
  };
  const FormSolution coarse = solve(temperature, Scheme::Eem, 0.1), fine = solve(temperature, Scheme::Eem, 0.05);
  const double timeError = formDifference(coarse, fine);
  const double eemGap = std::max(formDifference(coarse, solve(entropy, Scheme::Eem, 0.1)),
                                 formDifference(fine, solve(entropy, Scheme::Eem, 0.05)));
  std::printf("EEM at t = %.0f: entropy against temperature form %.2e; dt 0.1 against 0.05 %.2e\n", tEnd, eemGap,
              timeError);
  EXPECT_LT(eemGap, 1e-6 * timeError);

  std::vector<double> steps, gaps;
  for (double dt : {0.2, 0.1}) {
    steps.push_back(dt);
    gaps.push_back(formDifference(solve(temperature, Scheme::Midpoint, dt), solve(entropy, Scheme::Midpoint, dt)));
  }
  std::printf("midpoint: entropy against temperature form %.2e (dt 0.2), %.2e (dt 0.1)\n", gaps[0], gaps[1]);
  EXPECT_NEAR(logLogSlope(steps, gaps), 2.0, 0.3);
}

// Thermo-viscoelastic L-block: the branch (temperature-dependent viscosity) heats the block;
// E, L, J stay exact after the load and S never decreases.
TEST(ThermoviscoelasticLBlock, EemKeepsEnergyAndMomentaWhileTheBranchHeatsTheBlock) {
  const CompiledScene scene = loadScene(scenePath("lblock_thermoviscoelastic.xml"));
  const History h = run(*scene.model, Scheme::Eem, 0.05, 6.0);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  expectIsolatedBalances(h, "thermo-viscoelastic EEM dt 0.05");
  EXPECT_EQ(h.dissipated.back(), 0.0);  // the dissipation stays in the block as heat
  // the viscous production adds to the conductive one of the same block without a branch
  const CompiledScene elastic = loadScene(scenePath("lblock_thermoelastic.xml"));
  const History e = run(*elastic.model, Scheme::Eem, 0.05, 6.0);
  std::printf("entropy produced to t = 6: %.4e with the branch, %.4e without\n", h.entropy.back() - h.entropy.front(),
              e.entropy.back() - e.entropy.front());
  EXPECT_GT(h.entropy.back() - h.entropy.front(), 1.05 * (e.entropy.back() - e.entropy.front()));
}

// With beta = 0 and a constant viscosity the temperature field is passive: the motion is that of
// the isothermal viscoelastic solid, whose run reports the energy D_n its branch dissipates in
// each step. The thermal solid keeps that energy as heat (E exact) and its entropy grows in each
// step by at least D_n / theta_max (the viscous production; conduction adds a non-negative one).
TEST(ThermoviscoelasticSolid, ProducesAtLeastTheViscousDissipationOverTheTemperature) {
  const auto scene = [](const std::string& thermal) {
    return R"(<metriplex name="viscous_column"><simulation dt="0.05" t_end="2"/>
      <solid name="column" mesh="box" size="1 4 1" cells="1 4 1" lambda="500" mu="400" density="10" twist="3 8"
             branch_mu="300" viscosity="4" )" +
           thermal + "/></metriplex>";
  };
  const CompiledScene isothermal = loadSceneText(scene(""), scenePath("viscous_column.xml"));
  const History mechanical = run(*isothermal.model, Scheme::Eem, 0.05, 2.0);
  ASSERT_FALSE(mechanical.summary.failed);
  EXPECT_GT(mechanical.dissipated.back(), 1e-3 * std::abs(mechanical.energy.front()));
  const std::string capacity = R"(heat_capacity="20" conductivity="3" reference_temperature="300" temperature="300")";
  for (ThermalVariable variable : {ThermalVariable::Temperature, ThermalVariable::Entropy}) {
    const char* form = variable == ThermalVariable::Temperature ? "temperature form" : "entropy form";
    const CompiledScene thermal = loadSceneText(scene(capacity), scenePath("viscous_column.xml"), variable);
    const History heated = run(*thermal.model, Scheme::Eem, 0.05, 2.0);
    ASSERT_FALSE(heated.summary.failed) << form;
    ASSERT_EQ(mechanical.states.size(), heated.states.size()) << form;
    const SolidPlacement& column = thermal.solids.front();
    const Layout& layout = thermal.model->layout();
    const auto positions = [&](const History& h, std::size_t n) {
      return h.states[n].segment(layout.offset(Block::Position), layout.size(Block::Position));
    };
    const auto hottest = [&](std::size_t n) {
      double theta = 0.0;
      for (std::size_t a = 0; a < column.thermalDofs.size(); ++a)
        theta = std::max(theta, column.nodeTemperature(heated.states[n].data(), static_cast<int>(a)));
      return theta;
    };
    // S holds sum_a m_a kappa ln(theta_a / theta_R) near 0: its round-off is relative to the
    // total heat capacity (80 J/K here), not to S
    const double roundOff = kEntropyRoundOff * 20.0 * 4.0;
    double worstMargin = INFINITY;
    for (std::size_t n = 1; n < heated.states.size(); ++n) {
      EXPECT_LT((positions(heated, n) - positions(mechanical, n)).cwiseAbs().maxCoeff(), 1e-8) << form << n;
      const double dissipated = mechanical.dissipated[n] - mechanical.dissipated[n - 1];
      const double bound = dissipated / std::max(hottest(n - 1), hottest(n));
      const double production = heated.entropy[n] - heated.entropy[n - 1];
      EXPECT_GE(production, bound - roundOff) << form << " step " << n;
      worstMargin = std::min(worstMargin, production / bound);
    }
    std::printf("viscous column, %s: dissipated %.4e J, heated to %.2f K; production / (D / theta_max) >= %.6f\n", form,
                mechanical.dissipated.back(), hottest(heated.states.size() - 1), worstMargin);
    EXPECT_LT(std::abs(heated.energy.back() - heated.energy.front()), 1e-10 * std::abs(heated.energy.front())) << form;
  }
}

// ---------------------------------------------------------------------------------------------
// 6. L-block with Dirichlet temperatures: E' - E = W + Q and S' - S = S_boundary + production,
// production >= 0, at every step, with EEM and with eem4 (stage temperatures, docs/theory.md
// section 13.9).
TEST(DirichletLBlock, KeepsTheEnergyAndEntropyBalancesWithBoundaryHeatAtEveryStep) {
  const CompiledScene scene = loadScene(scenePath("lblock_thermal_dirichlet.xml"));
  const std::pair<Scheme, double> runs[] = {{Scheme::Eem, 0.05}, {Scheme::Eem4, 0.1}};
  for (const auto& [scheme, dt] : runs) {
    const History h = run(*scene.model, scheme, dt, 4.0);
    ASSERT_FALSE(h.summary.failed) << h.summary.failure;
    const std::string label = "Dirichlet L-block, " + schemeName(scheme);
    expectStepBalances(h, label.c_str());
    EXPECT_GT(std::abs(h.boundaryHeat.back()), 1.0);  // the held faces do exchange heat
  }
}

// ---------------------------------------------------------------------------------------------
// 6b. Flexible multibody with heat: a hot viscoelastic link on joints, linked to a coolant
// reservoir over its whole surface, is a closed system: E exact and S never decreasing, while
// the link cools.
TEST(CooledFlexiblePendulum, KeepsTheEnergyAndProducesEntropyWhileTheLinkCools) {
  const CompiledScene scene = loadScene(scenePath("cooled_flexible_pendulum.xml"));
  const History h = run(*scene.model, Scheme::Eem, 0.005, 1.0, scene.settings.newton);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  const SolidPlacement& link = scene.solids.front();
  const auto meanTemperature = [&](const VectorXd& z) {
    const int nodes = static_cast<int>(link.thermalDofs.size());
    double sum = 0.0;
    for (int a = 0; a < nodes; ++a) sum += link.nodeTemperature(z.data(), a) / nodes;
    return sum;
  };
  std::printf("cooled flexible pendulum: energy drift %.2e of %.3e, link mean temperature %.2f -> %.2f K\n",
              maxBalanceDrift(h), largestEnergy(h), meanTemperature(h.states.front()),
              meanTemperature(h.states.back()));
  EXPECT_LT(maxBalanceDrift(h), 1e-10 * largestEnergy(h));
  EXPECT_EQ(h.boundaryHeat.back(), 0.0);
  EXPECT_EQ(firstEntropyDecrease(h), -1);
  EXPECT_LT(meanTemperature(h.states.back()), meanTemperature(h.states.front()) - 0.1);
}

// ---------------------------------------------------------------------------------------------
// 7. IDA integrates the same semi-discrete thermoelastic model: EEM converges to IDA's tight
// solution at order 2 in positions and temperatures.
TEST(ThermoelasticLBlock, EemConvergesToTheIdaSolutionAtOrderTwo) {
  const CompiledScene scene = loadScene(scenePath("lblock_thermoelastic.xml"));
  const double tEnd = 0.5;
  const History ida = runIda(*scene.model, 1e-9, tEnd);
  ASSERT_FALSE(ida.summary.failed) << ida.summary.failure;
  const Layout& layout = scene.model->layout();
  for (Block block : {Block::Position, Block::Thermal}) {
    std::vector<double> steps, errors;
    for (double dt : {0.01, 0.005}) {
      const VectorXd eem = run(*scene.model, Scheme::Eem, dt, tEnd).states.back();
      steps.push_back(dt);
      errors.push_back(
          (eem - ida.states.back()).segment(layout.offset(block), layout.size(block)).cwiseAbs().maxCoeff());
    }
    std::printf("%s: EEM against IDA rtol 1e-9 at t = %.1f: %.3e (dt 0.01), %.3e (dt 0.005)\n",
                std::string(blockName(block)).c_str(), tEnd, errors[0], errors[1]);
    EXPECT_NEAR(logLogSlope(steps, errors), 2.0, 0.3) << blockName(block);
  }
}

// ---------------------------------------------------------------------------------------------
// 8. Bad input names the file, line and what is wrong.
void expectSceneError(const std::string& elements, const std::string& what, bool entropyForm = false) {
  const std::string text = std::string(R"(<metriplex name="bad"><simulation dt="0.1" t_end="1"/>)") + "\n" +
                           R"(<solid name="s" mesh="box" cells="1 1 1" young="1000" poisson="0.3" density="1" )" +
                           elements + "</metriplex>";
  try {
    loadSceneText(text, "bad.xml",
                  entropyForm ? std::optional<ThermalVariable>(ThermalVariable::Entropy) : std::nullopt);
    FAIL() << "accepted: " << elements;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.xml:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
  }
}

TEST(ThermalSolidInput, IsRefusedWithFileLineAndReason) {
  expectSceneError(R"(heat_capacity="-1"/>)", "heat_capacity");
  expectSceneError(R"(heat_capacity="1" conductivity="-2"/>)", "conductivity");
  expectSceneError(R"(heat_capacity="1" temperature="0"/>)", "temperature");
  expectSceneError(R"(conductivity="2"/>)", "needs a thermal solid");
  expectSceneError(R"(heat_capacity="1"/>
    <prescribed_temperature solid="s" surface="nowhere" temperature="300"/>)",
                   "no surface or node set 'nowhere'");
  expectSceneError(R"(/>
    <convection name="c" solid="s" surface="x0" coefficient="1" ambient="300"/>)",
                   "has no temperature field");
  expectSceneError(R"(heat_capacity="1"/>
    <prescribed_temperature solid="s" surface="x0" temperature="300"/>)",
                   "needs the temperature form", true);
  expectSceneError(R"(heat_capacity="1" viscosity_activation="0.01"/>)", "needs a viscous branch");
  expectSceneError(R"(heat_capacity="1"/>
    <prescribed_temperature solid="s" surface="x0" temperature="300"/>
    <prescribed_temperature solid="s" surface="x0" temperature="310"/>)",
                   "already has a prescribed temperature");
  expectSceneError(R"(heat_capacity="1"/>
    <prescribed_temperature solid="s" surface="x0" temperature="300"/>
    <initial_temperature solid="s" surface="x0" temperature="310"/>)",
                   "has a prescribed temperature");
}

}  // namespace
}  // namespace mpx::test
