// The rate form F(t, z, zdot) of whole scenes, as SUNDIALS IDA sees it: its tangent
// alpha dF/dz + beta dF/dzdot (engine/linear/assembler) against central differences, at a
// perturbed state with velocities and rates of their own size, on the multibody and lumped fixtures (every joint type,
// directors, GGL multipliers, dampers, thermal elements); FE cells' rate tangents are checked
// cell by cell in test_fe_dynamics. IDA's Newton converges only as well as this Jacobian is
// right.
#include "support.hpp"
#include "tangent_check.hpp"

#include "engine/linear/assembler.hpp"

#include <gtest/gtest.h>

namespace mpx::test {
namespace {

// F is linear in the rates, so a large difference step is exact there and keeps round-off of
// the large forces in F out of the small mass entries.
constexpr double kRateStep = 1e-2;

class RateJacobian : public ::testing::TestWithParam<const char*> {};

TEST_P(RateJacobian, MatchesCentralDifferences) {
  const CompiledScene scene = loadScene(scenePath(GetParam()));
  const Model& model = *scene.model;
  Assembler assembler(model, Component::LocalForm::Rate);
  Workspace workspace = model.makeWorkspace();
  VectorXd z = model.initialState() + 1e-3 * randomIsh(magnitudeAt(model, model.initialState()), 23);
  // velocities of their own size: dampers and friction take their rates from them, and a
  // scene that starts at rest would leave those terms at the round-off of the differences
  const int velocities = model.layout().offset(Block::Velocity), count = model.layout().size(Block::Velocity);
  z.segment(velocities, count) = randomIsh(magnitudeAt(model, z), 31).segment(velocities, count);
  const VectorXd zdot = randomIsh(magnitudeAt(model, z), 29);
  auto residual = [&](const VectorXd& y, const VectorXd& yp) {
    assembler.clear();
    assembler.addRate(model, workspace, {y.data(), yp.data(), 0.1, 1.0, 0.0}, 1.0);
    assembler.imposeRateMotions(model, y.data(), yp.data(), 0.1, 0.0);
    return VectorXd(assembler.residual());
  };
  for (const auto& [alpha, beta] : {std::pair{1.0, 0.0}, std::pair{0.0, 1.0}}) {
    assembler.clear();
    assembler.addRate(model, workspace, {z.data(), zdot.data(), 0.1, alpha, beta}, 1.0);
    assembler.imposeRateMotions(model, z.data(), zdot.data(), 0.1, beta);
    const MatrixXd analytic = MatrixXd(assembler.tangent());
    const bool byState = alpha > 0;  // a named copy: lambdas capture no structured binding (C++17)
    const VectorXd at = byState ? z : zdot;
    const MatrixXd numeric =
        centralDifferences([&](const VectorXd& x) { return byState ? residual(x, zdot) : residual(z, x); }, at,
                           magnitudeAt(model, at), byState ? 1e-6 : kRateStep);
    SCOPED_TRACE(byState ? "dF/dz" : "dF/dzdot");
    expectTangentMatches(model, analytic, numeric, magnitudeAt(model, at), 1e-5);
  }
}

// IDA's residual calls ask for no tangent (alpha = beta = 0): the residual and the flows are
// those of a full evaluation, bit for bit, and the tangent stays zero (multibody, lumped and
// thermal fixtures, and viscoelastic and thermo-viscoelastic solids, which skip the tangent).
TEST(ResidualOnlyEvaluation, MatchesTheFullOne) {
  for (const char* file : {"flyball_governor.xml", "damped_double_pendulum.xml", "two_thermo_springs.xml",
                           "thermo_visco_elastic.xml", "lblock_viscoelastic.xml", "lblock_thermoviscoelastic.xml"}) {
    SCOPED_TRACE(file);
    const CompiledScene scene = loadScene(scenePath(file));
    const Model& model = *scene.model;
    Assembler assembler(model, Component::LocalForm::Rate);
    Workspace workspace = model.makeWorkspace();
    const VectorXd z = model.initialState() + 1e-3 * randomIsh(magnitudeAt(model, model.initialState()), 23);
    const VectorXd zdot = randomIsh(magnitudeAt(model, z), 29);
    assembler.clear();
    assembler.addRate(model, workspace, {z.data(), zdot.data(), 0.1, 1.0, 0.5}, 1.0);
    const VectorXd full = assembler.residual();
    const Flows fullFlows = assembler.flows();
    assembler.clear();
    assembler.addRate(model, workspace, {z.data(), zdot.data(), 0.1, 0.0, 0.0}, 1.0);
    EXPECT_EQ((assembler.residual() - full).lpNorm<Eigen::Infinity>(), 0.0);
    EXPECT_EQ(assembler.flows().dissipated, fullFlows.dissipated);
    EXPECT_EQ(assembler.flows().boundaryHeat, fullFlows.boundaryHeat);
    const Eigen::SparseMatrix<double>& tangent = assembler.tangent();
    EXPECT_EQ(Eigen::Map<const VectorXd>(tangent.valuePtr(), tangent.nonZeros()).lpNorm<Eigen::Infinity>(), 0.0);
  }
}

INSTANTIATE_TEST_SUITE_P(FixtureScenes, RateJacobian,
                         ::testing::Values("flyball_governor.xml", "double_pendulum.xml", "damped_double_pendulum.xml",
                                           "heavy_top.xml", "free_floating_chain.xml", "two_thermo_springs.xml",
                                           "thermo_visco_elastic.xml", "damped_pendulum_spring.xml",
                                           "double_pendulum_penalty.xml", "damped_robot_arm.xml",
                                           "stiff_thermo_chain.xml", "heated_thermo_spring.xml", "thermal_block.xml"),
                         [](const auto& info) {
                           std::string name = info.param;
                           return name.substr(0, name.find('.'));
                         });

}  // namespace
}  // namespace mpx::test
