// Finite-element solids under EEM: the assembled step tangent of one hexahedron against
// central differences, the patch test and the balance of internal forces and moments, the
// tumbling L-block (elastic and viscoelastic) keeping energy, E + dissipated and both momenta
// where the midpoint rule does not, second order in time, the clamped viscoelastic cantilever,
// the flexible pendulum on joints, and the velocity-condensed Newton solve against a plain LU.
#include "support.hpp"
#include "tangent_check.hpp"

#include "engine/stepping/method.hpp"
#include "models/fe/material.hpp"

#include <gtest/gtest.h>
#include <Eigen/SparseLU>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <string>
#include <vector>

namespace mpx::test {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// ---------------------------------------------------------------------------------------------
// Shared helpers: scenes from files with edits, runs, and drifts measured after the load.

// A run of `scene` from t = 0 to tEnd at step dt with the scene's Newton settings.
SceneRun runScene(CompiledScene scene, Scheme scheme, double dt, double tEnd) {
  History h = run(*scene.model, scheme, dt, tEnd, scene.settings.newton);
  return {std::move(scene), std::move(h)};
}

// Index of the first recorded time at or after t.
std::size_t indexAt(const History& h, double t) {
  const auto it = std::lower_bound(h.time.begin(), h.time.end(), t - 1e-9);
  return static_cast<std::size_t>(it - h.time.begin());
}

// max_{n >= from} |s_n - s_from| / scale
double driftAfter(const std::vector<double>& series, std::size_t from, double scale) {
  double drift = 0.0;
  for (std::size_t n = from; n < series.size(); ++n)
    drift = std::max(drift, std::abs(series[n] - series[from]) / scale);
  return drift;
}

double driftAfter(const std::vector<Vec3>& series, std::size_t from, double scale) {
  double drift = 0.0;
  for (std::size_t n = from; n < series.size(); ++n) drift = std::max(drift, (series[n] - series[from]).norm() / scale);
  return drift;
}

// E + dissipated - external work - boundary heat of every recorded step.
std::vector<double> energyBalance(const History& h) {
  std::vector<double> balance;
  for (std::size_t n = 0; n < h.energy.size(); ++n)
    balance.push_back(h.energy[n] + h.dissipated[n] - h.externalWork[n] - h.boundaryHeat[n]);
  return balance;
}

// Largest |E + D - W - E0| of a loaded run, computed here from the history (not taken from the
// engine's own summary), and the scale it is judged against: the largest |E|, D or |W|.
struct LoadedBalance {
  double error, scale;
};
LoadedBalance loadedBalance(const History& h) {
  double scale = 0.0;
  for (std::size_t n = 0; n < h.energy.size(); ++n)
    scale = std::max({scale, std::abs(h.energy[n]), h.dissipated[n], std::abs(h.externalWork[n])});
  return {driftAfter(energyBalance(h), 0, 1.0), scale};
}

// Mass of the scene's first solid: the momentum of the state moving it at unit speed along x.
double solidMass(const CompiledScene& scene) {
  const SolidPlacement& solid = scene.solids.front();
  VectorXd z = scene.model->initialState();
  z.segment(scene.model->layout().offset(Block::Velocity), scene.model->layout().size(Block::Velocity)).setZero();
  for (std::size_t n = 0; n < solid.mesh->nodes.size(); ++n)
    z[solid.firstPositionDof + 3 * n + solid.velocityShift] = 1.0;
  Measures measures;
  scene.model->measure(z, measures);
  return measures.momentum.x();
}

// Largest distance of the nodes of a solid's surface from their reference positions.
double largestMotion(const std::vector<VectorXd>& states, const SolidPlacement& solid, const std::string& surface) {
  double motion = 0.0;
  for (const VectorXd& z : states)
    for (int n : solid.mesh->nodesOf(surface))
      motion = std::max(motion, (z.segment<3>(solid.firstPositionDof + 3 * n) - solid.mesh->nodes[n]).norm());
  return motion;
}

// Measures::constraintViolation (max |Phi|) of every recorded state.
double maxViolation(const Model& model, const History& h) {
  Measures measures;
  double largest = 0.0;
  for (const VectorXd& z : h.states) {
    model.measure(z, measures);
    largest = std::max(largest, measures.constraintViolation);
  }
  return largest;
}

// ---------------------------------------------------------------------------------------------
// 1. The assembled step tangent of one hexahedron, and of the Gmsh tetrahedral bar (moving,
// deformed, with viscous strains) against central differences of the step residual, for each
// law and scheme.
struct CellCase {
  const char* name;
  const char* material;  // attributes of the <solid>
  Scheme scheme;
  const char* mesh;
  double perturbation;  // of the moved state, relative to the dofs' magnitudes (cells of size 1 or 0.5)
};

void PrintTo(const CellCase& c, std::ostream* out) { *out << c.name << "_" << schemeName(c.scheme); }

std::string oneCell(const CellCase& c) {
  return std::string(R"(<metriplex name="one_cell"><simulation dt="0.1" t_end="10"/>
    <solid name="cell" young="1000" poisson="0.3" density="10" velocity="0.1 -0.2 0.3"
           angular_velocity="0.5 0.2 -0.4" )") +
         c.mesh + " " + c.material + "/></metriplex>";
}

class CellTangent : public ::testing::TestWithParam<CellCase> {};

TEST_P(CellTangent, MatchesFiniteDifferencesAtAMovedState) {
  // labelled as a file in scenes/, where the Gmsh mesh path is relative to
  const CompiledScene scene = loadSceneText(oneCell(GetParam()), scenePath("tangent_cell.xml"));
  const Model& model = *scene.model;
  Integrator integrator(model, GetParam().scheme, NewtonSettings{});
  // zOld deformed, moved and with viscous strains; the Newton unknowns (the end state, or
  // eem4's stage values) a generic step away from it
  const double size = GetParam().perturbation;
  const int stages = integrator.stageCount();
  const VectorXd zOld = model.initialState() + size * randomIsh(magnitudeAt(model, model.initialState()), 3);
  const VectorXd unknowns =
      zOld.replicate(stages, 1) + 1e-2 * randomIsh(magnitudeAt(model, zOld).replicate(stages, 1), 5);
  const double t = 0.7, dt = 0.1;
  const MatrixXd analytic(integrator.evaluate(zOld, unknowns, t, dt).tangent());
  const auto residual = [&](const VectorXd& z) -> VectorXd { return integrator.evaluate(zOld, z, t, dt).residual(); };
  const VectorXd magnitude = unknowns.cwiseAbs() + model.dofScale().replicate(stages, 1);
  const MatrixXd numeric = centralDifferences(residual, unknowns, magnitude, 1e-6);
  const Mismatch worst = worstRowMismatch(analytic, numeric, magnitude);
  std::printf("%s, %s: worst relative tangent mismatch %.2e (row %ld, column %ld)\n", GetParam().name,
              schemeName(GetParam().scheme).c_str(), worst.relative, static_cast<long>(worst.row),
              static_cast<long>(worst.col));
  expectTangentMatches(model, analytic, numeric, magnitude, 1e-6);
}

std::vector<CellCase> cellCases() {
  const std::pair<const char*, const char*> laws[] = {
      {"svk", R"(material="svk")"},
      {"neo_hooke", R"(material="neo_hooke")"},
      {"neo_hooke_viscous", R"(material="neo_hooke" branch_lambda="200" branch_mu="50" viscosity="100")"}};
  std::vector<CellCase> cases;
  for (const auto& [name, material] : laws)
    for (Scheme scheme : {Scheme::Eem, Scheme::Midpoint, Scheme::Eem4})
      cases.push_back({name, material, scheme, R"(mesh="box" cells="1 1 1")", 5e-2});
  // the bar's tetrahedra are 0.5 across in a body 4 long: a smaller perturbation keeps them uninverted
  cases.push_back({"tet4_neo_hooke_viscous", laws[2].second, Scheme::Eem, R"(mesh="meshes/bar_tets.msh")", 5e-3});
  return cases;
}

INSTANTIATE_TEST_SUITE_P(EveryLaw, CellTangent, ::testing::ValuesIn(cellCases()),
                         [](const ::testing::TestParamInfo<CellCase>& info) {
                           return std::string(info.param.name) + "_" + schemeName(info.param.scheme);
                         });

// ---------------------------------------------------------------------------------------------
// 2. Internal nodal forces: the momentum rows of the EEM residual at rest (zOld = zNew, v = 0,
// no loads), which are exactly sum_q w F S dN_a/dX there.
constexpr double kYoung = 1000.0, kPoisson = 0.3;

const char* const kCube = R"(<metriplex name="cube"><simulation dt="0.1" t_end="1"/>
  <solid name="cube" mesh="box" size="2 2 2" cells="2 2 2" material="neo_hooke" young="1000" poisson="0.3"
         density="10"/></metriplex>)";

// Node n's internal force in state z (velocities zeroed): its momentum rows at rest.
std::vector<Vec3> internalForces(const CompiledScene& scene, VectorXd z) {
  const Model& model = *scene.model;
  z.segment(model.layout().offset(Block::Velocity), model.layout().size(Block::Velocity)).setZero();
  Integrator integrator(model, Scheme::Eem, NewtonSettings{});
  const VectorXd& r = integrator.evaluate(z, z, 0.0, 0.1).residual();
  const SolidPlacement& solid = scene.solids.front();
  std::vector<Vec3> forces;
  for (std::size_t n = 0; n < solid.mesh->nodes.size(); ++n)
    forces.push_back(r.segment<3>(solid.firstPositionDof + 3 * n + solid.velocityShift));
  return forces;
}

// The state with node n at x(X_n).
template <class Map>
VectorXd deformed(const CompiledScene& scene, const Map& map) {
  const SolidPlacement& solid = scene.solids.front();
  VectorXd z = scene.model->initialState();
  for (std::size_t n = 0; n < solid.mesh->nodes.size(); ++n)
    z.segment<3>(solid.firstPositionDof + 3 * n) = map(solid.mesh->nodes[n]);
  return z;
}

// Under x = A X + b the stress P = A S(A^T A) is uniform, so node a's force is the traction
// of P on the boundary, P sum_faces int N_a N dA (a quarter of each rectangular face's area
// vector), and the one interior node, (1, 1, 1), carries none.
TEST(InternalForces, PassThePatchTestUnderAHomogeneousDeformation) {
  const CompiledScene scene = loadSceneText(kCube, "cube");
  const Mesh& mesh = *scene.solids.front().mesh;
  Mat3 A;
  A << 1.05, 0.02, -0.03, -0.04, 0.97, 0.01, 0.02, 0.05, 1.08;
  const Vec3 b(0.3, -0.2, 0.1);
  const std::vector<Vec3> forces =
      internalForces(scene, deformed(scene, [&](const Vec3& X) { return Vec3(A * X + b); }));

  const Mat3 P = A * NeoHooke(LameParameters::fromYoung(kYoung, kPoisson)).stress(A.transpose() * A);
  std::vector<Vec3> expected(mesh.nodes.size(), Vec3::Zero());
  for (const Face& face : mesh.boundaryFaces()) {
    const auto& x = mesh.nodes;
    const Vec3 areaVector = (x[face.nodes[1]] - x[face.nodes[0]]).cross(x[face.nodes[3]] - x[face.nodes[0]]);
    for (int a = 0; a < face.count; ++a) expected[face.nodes[a]] += P * areaVector / 4;
  }
  const double scale = P.norm() * 1.0;  // stress times a cell face's area
  double worst = 0.0, interior = -1.0;
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    worst = std::max(worst, (forces[n] - expected[n]).norm() / scale);
    if ((mesh.nodes[n] - Vec3::Ones()).norm() < 1e-12) interior = forces[n].norm() / scale;
  }
  std::printf("patch test, |P| = %.3g: interior node |f| %.2e, worst |f - traction load| %.2e (relative to |P| A)\n",
              P.norm(), interior, worst);
  ASSERT_GE(interior, 0.0) << "no node at (1, 1, 1)";
  EXPECT_LE(interior, 1e-12);
  EXPECT_LE(worst, 1e-12);
}

// F S F^T is symmetric at every point: the internal forces of any deformation sum to zero
// and exert no moment (the balance EEM's momentum conservation rests on).
TEST(InternalForces, HaveNoResultantForceOrMomentInAGeneralDeformation) {
  const CompiledScene scene = loadSceneText(kCube, "cube");
  const VectorXd z = deformed(scene, [](const Vec3& X) {
    return Vec3(X.x() + 0.1 * std::sin(X.y()) + 0.5, X.y() + 0.08 * X.x() * X.z(), X.z() - 0.05 * X.y() * X.y());
  });
  const std::vector<Vec3> forces = internalForces(scene, z);
  const SolidPlacement& solid = scene.solids.front();
  Vec3 resultant = Vec3::Zero(), moment = Vec3::Zero();
  double largest = 0.0, reach = 0.0;
  for (std::size_t n = 0; n < forces.size(); ++n) {
    const Vec3 x = z.segment<3>(solid.firstPositionDof + 3 * n);
    resultant += forces[n];
    moment += x.cross(forces[n]);
    largest = std::max(largest, forces[n].norm());
    reach = std::max(reach, x.norm());
  }
  std::printf("general deformation, largest |f_a| %.3g: |sum f_a| %.2e, |sum x_a x f_a| %.2e (relative)\n", largest,
              resultant.norm() / largest, moment.norm() / (largest * reach));
  EXPECT_GT(largest, 1.0);  // the deformation does load the nodes
  EXPECT_LE(resultant.norm(), 1e-13 * largest);
  EXPECT_LE(moment.norm(), 1e-13 * largest * reach);
}

// ---------------------------------------------------------------------------------------------
// 3, 4. The tumbling L-blocks: dead tractions with the hat profile for t <= 5, free after.
constexpr double kLoadEnd = 5.0;

// The conserved figures of a run after the load: energy (or E + dissipated - work, which is 0
// from rest) relative to E(5), P against the momentum scale sqrt(2 m E(5)), J relative to |J(5)|.
struct AfterLoad {
  double energy, momentum, angularMomentum;
};

AfterLoad driftsAfterLoad(const SceneRun& r, const std::vector<double>& conserved) {
  const History& h = r.history;
  const std::size_t from = indexAt(h, kLoadEnd);
  const double momentumScale = std::sqrt(2.0 * solidMass(r.scene) * h.energy[from]);
  return {driftAfter(conserved, from, h.energy[from]), driftAfter(h.momentum, from, momentumScale),
          driftAfter(h.angularMomentum, from, h.angularMomentum[from].norm())};
}

// eem4 on a tumbling, deforming viscoelastic cell (Neo-Hooke and a Maxwell branch) at a large
// step: E + dissipated closes at every step (measured 1e-11 of the energy), the branch dissipates at every step, and
// the linear and angular momentum stay put.
TEST(ViscoelasticCell, Eem4KeepsEnergyPlusDissipationAndMomenta) {
  const CellCase cell{"neo_hooke_viscous", R"(material="neo_hooke" branch_lambda="200" branch_mu="50" viscosity="10")",
                      Scheme::Eem4, R"(mesh="box" cells="1 1 1")", 0.0};
  const CompiledScene scene = loadSceneText(oneCell(cell), scenePath("tangent_cell.xml"));
  const History h = run(*scene.model, Scheme::Eem4, 0.1, 10.0);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  const double scale = largestEnergy(h);
  double worstStep = 0.0, leastDissipation = INFINITY;
  for (std::size_t n = 1; n < h.energy.size(); ++n) {
    auto balance = [&](std::size_t k) { return h.energy[k] + h.dissipated[k]; };
    worstStep = std::max(worstStep, std::abs(balance(n) - balance(n - 1)) / scale);
    leastDissipation = std::min(leastDissipation, h.dissipated[n] - h.dissipated[n - 1]);
  }
  const double momentum = (h.momentum.back() - h.momentum.front()).norm(),
               angular = (h.angularMomentum.back() - h.angularMomentum.front()).norm();
  std::printf(
      "viscoelastic cell, eem4 dt 0.1: worst step balance %.2e, least dissipation per step %.2e, "
      "drift of P %.2e, J %.2e\n",
      worstStep, leastDissipation, momentum, angular);
  // to Newton's tolerance: the branch's correction is a ratio of small quantities where the cell
  // turns almost rigidly (docs/theory.md section 13.4)
  EXPECT_LT(worstStep, 1e-10);
  EXPECT_GT(leastDissipation, 0.0);
  EXPECT_LT(momentum, 1e-12 * std::max(1.0, h.momentum.front().norm()));
  EXPECT_LT(angular, 1e-11 * std::max(1.0, h.angularMomentum.front().norm()));
}

// eem4 at the scene's step, also in the loaded phase: E + D - W closes at every step, and after
// the load E, P and J stay put.
TEST(TumblingLBlock, Eem4ConservesEnergyAndMomenta) {
  const SceneRun eem4 = runScene(loadScene(scenePath("lblock_elastic.xml")), Scheme::Eem4, 0.1, 20.0);
  ASSERT_FALSE(eem4.history.summary.failed) << eem4.history.summary.failure;
  const AfterLoad drift = driftsAfterLoad(eem4, eem4.history.energy);
  const double balance = maxBalanceDrift(eem4.history) / largestEnergy(eem4.history);
  std::printf("elastic L-block, eem4 dt 0.1: balance %.2e over t 0..20; t 5..20: drift of E %.2e, P %.2e, J %.2e\n",
              balance, drift.energy, drift.momentum, drift.angularMomentum);
  EXPECT_LE(balance, 1e-11);
  EXPECT_LE(drift.energy, 1e-9);
  EXPECT_LE(drift.momentum, 1e-9);
  EXPECT_LE(drift.angularMomentum, 1e-9);
}

TEST(TumblingLBlock, EemConservesEnergyAndMomentaWhereMidpointDoesNot) {
  const SceneRun eem = runScene(loadScene(scenePath("lblock_elastic.xml")), Scheme::Eem, 0.1, 50.0);
  ASSERT_FALSE(eem.history.summary.failed) << eem.history.summary.failure;
  const AfterLoad drift = driftsAfterLoad(eem, eem.history.energy);
  std::printf("elastic L-block, EEM dt 0.1, t 5..50: drift of E %.2e, P %.2e, J %.2e\n", drift.energy, drift.momentum,
              drift.angularMomentum);
  EXPECT_LE(drift.energy, 1e-9);
  EXPECT_LE(drift.momentum, 1e-9);
  EXPECT_LE(drift.angularMomentum, 1e-9);

  const SceneRun midpoint = runScene(loadScene(scenePath("lblock_elastic.xml")), Scheme::Midpoint, 0.1, 20.0);
  const History& m = midpoint.history;
  if (m.summary.failed) {
    std::printf("elastic L-block, midpoint dt 0.1: failed at step %d (t = %g): %s\n", m.summary.failedStep,
                m.summary.failedTime, m.summary.failure.c_str());
    return;
  }
  const double midpointDrift = driftAfter(m.energy, indexAt(m, kLoadEnd), m.energy[indexAt(m, kLoadEnd)]);
  std::printf("elastic L-block, midpoint dt 0.1, t 5..20: drift of E %.2e (%.0fx EEM's over t 5..50)\n", midpointDrift,
              midpointDrift / drift.energy);
  EXPECT_GE(midpointDrift, 100.0 * drift.energy);
  EXPECT_GT(midpointDrift, 1e-4);
}

TEST(ViscoelasticLBlock, EemKeepsEnergyPlusDissipationAndMomentaWhileEnergyDecays) {
  const SceneRun r = runScene(loadScene(scenePath("lblock_viscoelastic.xml")), Scheme::Eem, 0.25, 20.0);
  const History& h = r.history;
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  const AfterLoad drift = driftsAfterLoad(r, energyBalance(h));
  // steps after the load: E never rises, dissipated energy never falls (up to round-off)
  const std::size_t from = indexAt(h, kLoadEnd);
  double largestRise = -INFINITY, largestFall = -INFINITY;
  for (std::size_t n = from + 1; n < h.energy.size(); ++n) {
    largestRise = std::max(largestRise, (h.energy[n] - h.energy[n - 1]) / h.energy[from]);
    largestFall = std::max(largestFall, (h.dissipated[n - 1] - h.dissipated[n]) / h.energy[from]);
  }
  std::printf(
      "viscoelastic L-block, EEM dt 0.25, t 5..20: drift of E + D %.2e, P %.2e, J %.2e; E fell to %.3f E(5); "
      "largest step rise of E %.2e, fall of D %.2e\n",
      drift.energy, drift.momentum, drift.angularMomentum, h.energy.back() / h.energy[from], largestRise, largestFall);
  EXPECT_LE(drift.energy, 1e-9);
  EXPECT_LE(drift.momentum, 1e-9);
  EXPECT_LE(drift.angularMomentum, 1e-9);
  EXPECT_LE(largestRise, 1e-12);
  EXPECT_LE(largestFall, 1e-12);
  EXPECT_LT(h.energy.back(), 0.9 * h.energy[from]);  // the branch does dissipate
}

// ---------------------------------------------------------------------------------------------
// 5. Order in time: the L-block under its load up to t = 1, from a largest step halved a few
// times.
// The differences of successive final positions (Euclidean norm) fall by 2^p per halving for
// a scheme of order p: a Richardson estimate of the error that needs no reference run. The
// L-block's stiff modes keep dt = 0.1 outside EEM's asymptotic range (slope 1.7 there); eem4
// from dt = 0.025 (slopes 2.6 and 3.7 from dt = 0.1).
struct OrderCase {
  Scheme scheme;
  double largestStep;
  int halvings;
};

class TimeOrder : public ::testing::TestWithParam<OrderCase> {};

TEST_P(TimeOrder, IsTheSchemesOnTheLoadedLBlock) {
  const CompiledScene scene = loadScene(scenePath("lblock_elastic.xml"));
  const OrderCase c = GetParam();
  const int positions = scene.model->layout().size(Block::Position), order = schemeOrder(c.scheme);
  std::vector<VectorXd> finals;
  for (int k = 0; k <= c.halvings; ++k) {
    const double dt = std::ldexp(c.largestStep, -k);
    const History h = run(*scene.model, c.scheme, dt, 1.0, scene.settings.newton);
    ASSERT_FALSE(h.summary.failed) << "dt " << dt << ": " << h.summary.failure;
    finals.push_back(h.states.back().head(positions));
  }
  std::vector<double> differences;
  for (std::size_t k = 0; k + 1 < finals.size(); ++k) differences.push_back((finals[k] - finals[k + 1]).norm());
  std::string table;
  for (std::size_t k = 0; k + 1 < differences.size(); ++k) {
    const double slope = std::log2(differences[k] / differences[k + 1]);
    table += (k ? ", " : "") + std::to_string(slope).substr(0, 5);
    EXPECT_GE(slope, order - 0.2) << "halving " << k;
    EXPECT_LE(slope, order + 0.2) << "halving " << k;
  }
  std::printf("L-block to t = 1, %s, dt %g halved %d times: |x(dt) - x(dt/2)| from %.3e to %.3e, slopes %s\n",
              schemeName(c.scheme).c_str(), c.largestStep, c.halvings, differences.front(), differences.back(),
              table.c_str());
}

INSTANTIATE_TEST_SUITE_P(Schemes, TimeOrder,
                         ::testing::Values(OrderCase{Scheme::Eem, 0.05, 4}, OrderCase{Scheme::Midpoint, 0.05, 4},
                                           OrderCase{Scheme::Eem4, 0.025, 2}),
                         [](const ::testing::TestParamInfo<OrderCase>& info) { return schemeName(info.param.scheme); });

// ---------------------------------------------------------------------------------------------
// 6. The viscoelastic cantilever, pulled for t <= 5 and relaxing after: its clamped face
// stays put and E + D - W is exact.
TEST(ViscoelasticCantilever, ClampHoldsAndEnergyBalanceIsExactWhileItRelaxes) {
  const SceneRun r = runScene(loadScene(scenePath("viscoelastic_cantilever.xml")), Scheme::Eem, 0.02, 6.0);
  const History& h = r.history;
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  const SolidPlacement& bar = r.scene.solids.front();
  const double clampMotion = largestMotion(h.states, bar, "x0");
  const double peak = *std::max_element(h.energy.begin(), h.energy.end());
  const auto [error, scale] = loadedBalance(h);
  const double balanceError = error / scale;
  const double atLoadEnd = h.energy[indexAt(h, kLoadEnd)];
  std::printf(
      "cantilever, EEM dt 0.02 to t = 6: clamp moved %.2e; |E + D - W - E0| %.2e of %.3g; E(6) = %.3f peak, "
      "%.3f E(5); W = %.3g, D = %.3g\n",
      clampMotion, balanceError, scale, h.energy.back() / peak, h.energy.back() / atLoadEnd, h.externalWork.back(),
      h.dissipated.back());
  EXPECT_LE(clampMotion, 1e-14);
  EXPECT_LE(balanceError, 1e-9);
  EXPECT_LT(h.energy.back(), atLoadEnd);  // relaxing once the pull stops
  EXPECT_GT(h.dissipated.back(), 0.0);
}

// The Gmsh tetrahedral bar, clamped and bent by a traction pulse: E - W exact (St. Venant-
// Kirchhoff, no dissipation), the clamped face fixed.
TEST(TetrahedralBar, ClampHoldsAndEnergyMinusWorkIsExact) {
  const SceneRun r = runScene(loadScene(scenePath("tet_bar.xml")), Scheme::Eem, 0.01, 1.5);
  const History& h = r.history;
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  const SolidPlacement& bar = r.scene.solids.front();
  const double clampMotion = largestMotion(h.states, bar, "left");
  const auto [error, scale] = loadedBalance(h);
  const double balanceError = error / scale;
  std::printf("tet bar (%zu tets), EEM dt 0.01 to t = 1.5: clamp moved %.2e; |E - W - E0| %.2e of %.3g\n",
              bar.mesh->cells.size(), clampMotion, balanceError, scale);
  EXPECT_LE(clampMotion, 1e-14);
  EXPECT_LE(balanceError, 1e-9);
  EXPECT_GT(scale, 0.0);
}

// IDA on the same bar: supports enter its rate form as dv/dt = 0, so the clamped face stays put,
// and its tip follows EEM's at a small step.
TEST(TetrahedralBar, IdaHoldsTheClampAndFollowsEem) {
  const CompiledScene scene = loadScene(scenePath("tet_bar.xml"));
  MethodParameters parameters;
  parameters.dt = 0.1;
  parameters.tEnd = 1.0;
  parameters.relativeTolerance = parameters.absoluteTolerance = 1e-8;
  std::vector<VectorXd> ida;
  const RunSummary summary =
      runMethod(*scene.model, *methodByName("ida"), parameters, [&](const StepRecord& r) { ida.push_back(*r.state); });
  ASSERT_FALSE(summary.failed) << summary.failure;
  const History eem = run(*scene.model, Scheme::Eem, 1e-3, 1.0, scene.settings.newton);
  const SolidPlacement& bar = scene.solids.front();
  const double clampMotion = largestMotion(ida, bar, "left");
  const int tip = bar.firstPositionDof + 3 * bar.mesh->nodesOf("right").front();
  const Vec3 idaTip = ida.back().segment<3>(tip), eemTip = eem.states.back().segment<3>(tip);
  const double deflection = (eemTip - bar.mesh->nodes[bar.mesh->nodesOf("right").front()]).norm();
  std::printf(
      "tet bar, IDA rtol 1e-8 to t = 1: clamp moved %.2e; |tip IDA - tip EEM(dt 1e-3)| = %.2e of deflection %.3f\n",
      clampMotion, (idaTip - eemTip).norm(), deflection);
  EXPECT_LE(clampMotion, 1e-12);
  EXPECT_LE((idaTip - eemTip).norm(), 1e-3 * deflection);
}

// A prescribed displacement u(t) = 0.5 sin(pi t / 2) on the end face: the face sits exactly at
// X + u(t) after every step, the clamped face does not move, and E + D - W is exact (the
// reaction's work is the external work).
TEST(StretchedBar, EndFaceFollowsThePrescribedDisplacementAndTheBalanceIsExact) {
  const SceneRun r = runScene(loadScene(scenePath("stretched_bar.xml")), Scheme::Eem, 0.02, 3.0);
  const History& h = r.history;
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  const SolidPlacement& bar = r.scene.solids.front();
  double offTrack = 0.0;
  for (std::size_t n = 0; n < h.states.size(); ++n) {
    const double u = h.time[n] <= 2.0 ? 0.5 * std::sin(M_PI * h.time[n] / 2.0) : 0.0;
    for (int node : bar.mesh->nodesOf("x1")) {
      const Vec3 expected = bar.mesh->nodes[node] + Vec3(u, 0.0, 0.0);
      offTrack = std::max(offTrack, (h.states[n].segment<3>(bar.firstPositionDof + 3 * node) - expected).norm());
    }
  }
  const double clampMotion = largestMotion(h.states, bar, "x0");
  const auto [error, scale] = loadedBalance(h);
  const double balanceError = error / scale;
  std::printf(
      "stretched bar, EEM dt 0.02 to t = 3: end face off its track by %.2e, clamp moved %.2e; "
      "|E + D - W - E0| %.2e of %.3g; D = %.3g\n",
      offTrack, clampMotion, balanceError, scale, h.dissipated.back());
  EXPECT_LE(offTrack, 1e-12);
  EXPECT_LE(clampMotion, 1e-14);
  EXPECT_LE(balanceError, 1e-9);
  EXPECT_GT(h.dissipated.back(), 0.0);
}

// Consistent nodal loads add up to the declared resultants: a free block under a total traction
// force F on one face and a body force density b gains momentum (F + b V) t (V = 2), which EEM's
// momentum rows reproduce exactly; the loads' work is the external work.
TEST(SolidLoads, TractionAndBodyForceSumToTheirResultants) {
  const std::string xml = R"(<metriplex name="loads"><simulation dt="0.05" t_end="1"/>
    <solid name="block" mesh="box" size="2 1 1" cells="2 1 1" material="svk" young="1000" poisson="0.3" density="10"/>
    <traction name="pull" solid="block" surface="x1" total_force="3 -1 2"/>
    <body_force name="weight" solid="block" force_density="0.5 0.25 -1"/></metriplex>)";
  const SceneRun r = runScene(loadSceneText(xml, "loads"), Scheme::Eem, 0.05, 1.0);
  const History& h = r.history;
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  const Vec3 resultant = Vec3(3, -1, 2) + 2.0 * Vec3(0.5, 0.25, -1);
  const double momentumError = (h.momentum.back() - resultant * h.time.back()).norm() / resultant.norm();
  const auto [error, scale] = loadedBalance(h);
  std::printf("loaded block, EEM dt 0.05 to t = 1: |P - (F + bV) t| / |F + bV| = %.2e; |E - W - E0| %.2e of %.3g\n",
              momentumError, error / scale, scale);
  EXPECT_LE(momentumError, 1e-12);
  EXPECT_LE(error / scale, 1e-9);
}

// ---------------------------------------------------------------------------------------------
// 7. The flexible pendulum: a viscoelastic FE link on a hub, released from rest (E0 = 0).
// The balance is judged against the link's potential scale m g L (m = 8, L = 2).
TEST(FlexiblePendulum, EnergyBalanceAndJointsHoldToRoundOff) {
  const SceneRun r = runScene(loadScene(scenePath("flexible_pendulum.xml")), Scheme::Eem, 0.005, 0.5);
  const History& h = r.history;
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  const double potentialScale = 8.0 * 9.81 * 2.0;
  const double balanceError = driftAfter(energyBalance(h), 0, potentialScale);
  const double violation = maxViolation(*r.scene.model, h);
  // how far the free end (x = 2) fell: the link did swing
  const SolidPlacement& link = r.scene.solids.front();
  const int tipY = link.firstPositionDof + 3 * link.mesh->nodesOf("x1").front() + 1;
  const double drop = h.states.front()[tipY] - h.states.back()[tipY];
  std::printf(
      "flexible pendulum, EEM dt 0.005 to t = 0.5: |E + D - E0| %.2e m g L, max constraint violation %.2e; "
      "tip fell %.3f, D = %.3g\n",
      balanceError, violation, drop, h.dissipated.back());
  EXPECT_LE(balanceError, 1e-9);
  EXPECT_LE(violation, 1e-9);
  EXPECT_GT(drop, 0.1);
  EXPECT_GT(h.dissipated.back(), 0.0);
}

// The same pendulum with every joint enforced by a penalty (kappa = 1e8): the penalty energy is
// part of E, so the balance stays exact while the joints hold to about force / kappa.
TEST(FlexiblePendulum, PenaltyJointsKeepTheBalanceAndHoldToForceOverStiffness) {
  std::string text = readFile(scenePath("flexible_pendulum.xml"));
  text.replace(text.find("<anchor"), 0, R"(<constraints enforcement="penalty" stiffness="1e8"/>
  )");
  const SceneRun r = runScene(loadSceneText(text, scenePath("flexible_pendulum_penalty.xml")), Scheme::Eem, 0.005, 0.5);
  const History& h = r.history;
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  const double balanceError = driftAfter(energyBalance(h), 0, 8.0 * 9.81 * 2.0);
  const double violation = maxViolation(*r.scene.model, h);
  std::printf("flexible pendulum, penalty 1e8: |E + D - E0| %.2e m g L, max constraint violation %.2e\n", balanceError,
              violation);
  EXPECT_EQ(r.scene.model->layout().size(Block::Multiplier), 0);
  EXPECT_LE(balanceError, 1e-9);
  EXPECT_LE(violation, 1e-5);
}

// ---------------------------------------------------------------------------------------------
// 8. The velocity-condensed Newton solve against a plain sparse LU of the whole tangent, at a
// generic step of FE scenes (clamps, joints with multipliers) and a rigid multibody scene, for
// EEM, midpoint and eem4: the condensed increment solves K dz = -r to round-off, and agrees with
// the plain LU's to the conditioning of the saddle-point systems of multiplier scenes. What
// simplified Newton relies on holds too: the factorisation answers alike after the tangent is
// re-assembled elsewhere, and an evaluation of the residual alone gives the full one's residual
// and flows (bit for bit, and for eem4 to round-off) and leaves the last tangent evaluated in place.
class CondensedNewton : public ::testing::TestWithParam<const char*> {};

TEST_P(CondensedNewton, AgreesWithAPlainSparseLu) {
  const CompiledScene scene = loadScene(scenePath(GetParam()));
  const Model& model = *scene.model;
  const Layout& layout = model.layout();
  const VectorXd zOld = model.initialState() + 1e-2 * randomIsh(magnitudeAt(model, model.initialState()), 17);
  for (Scheme scheme : {Scheme::Eem, Scheme::Midpoint, Scheme::Eem4}) {
    Integrator integrator(model, scheme, scene.settings.newton);
    // the Newton unknowns: the end state, or eem4's stage values (its stage system is condensed
    // stage by stage)
    const int stages = integrator.stageCount();
    const VectorXd scale = magnitudeAt(model, zOld).replicate(stages, 1);
    const VectorXd unknowns = zOld.replicate(stages, 1) + 1e-2 * randomIsh(scale, 19);
    const VectorXd weight = (unknowns.cwiseAbs() + model.dofScale().replicate(stages, 1)).cwiseInverse();
    const Assembler& system = integrator.evaluate(zOld, unknowns, 2.0, 0.1);
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
    lu.compute(system.tangent());
    ASSERT_EQ(lu.info(), Eigen::Success) << lu.lastErrorMessage();
    const VectorXd plain = -lu.solve(system.residual());

    CondensedSolver condensed(layout, system.tangent());
    ASSERT_TRUE(condensed.factorize(system.tangent(), false));
    VectorXd increment(unknowns.size());
    condensed.solve(system.residual(), increment);
    // every dof weighed by its magnitude, so that positions and velocities compare alike
    const double difference = (increment - plain).cwiseProduct(weight).cwiseAbs().maxCoeff() /
                              plain.cwiseProduct(weight).cwiseAbs().maxCoeff();
    const VectorXd defect = system.tangent() * increment + system.residual();
    const double backwardError =
        defect.norm() / (system.residual().norm() + system.tangent().norm() * increment.norm());
    std::printf("%s, %s: condensed %d of %d unknowns, backward error %.2e, relative difference to plain LU %.2e\n",
                GetParam(), schemeName(scheme).c_str(), condensed.condensedSize(), static_cast<int>(unknowns.size()),
                backwardError, difference);
    // velocities and internal variables (per quadrature point, per Maxwell element) eliminated
    // at every stage
    EXPECT_EQ(condensed.condensedSize(),
              stages * (layout.total() - layout.size(Block::Velocity) - layout.size(Block::Internal)));
    EXPECT_LE(backwardError, 1e-14);
    EXPECT_LE(difference, 1e-8);

    const VectorXd residual = system.residual();
    const Flows flows = system.flows();
    auto values = [](const Eigen::SparseMatrix<double>& m) {
      return VectorXd(Eigen::Map<const VectorXd>(m.valuePtr(), m.nonZeros()));
    };
    const VectorXd elsewhere = unknowns + 1e-2 * randomIsh(scale, 23);
    const VectorXd tangentElsewhere = values(integrator.evaluate(zOld, elsewhere, 2.0, 0.1).tangent());
    VectorXd again(unknowns.size());
    condensed.solve(residual, again);
    EXPECT_EQ((again - increment).lpNorm<Eigen::Infinity>(), 0.0);
    // (eem4's residual alone sums the stages of each solid cell and constraint after the other
    // components, in another order: the same to round-off)
    integrator.evaluate(zOld, unknowns, 2.0, 0.1, false);
    const double roundOff = stages > 1 ? 1e-14 : 0.0;
    EXPECT_LE((system.residual() - residual).lpNorm<Eigen::Infinity>(), roundOff * residual.lpNorm<Eigen::Infinity>());
    EXPECT_LE(std::abs(system.flows().dissipated - flows.dissipated), roundOff * std::abs(flows.dissipated));
    EXPECT_LE(std::abs(system.flows().externalWork - flows.externalWork), roundOff * std::abs(flows.externalWork));
    std::printf("  residual alone: differs by %.2e of the largest residual entry\n",
                (system.residual() - residual).lpNorm<Eigen::Infinity>() / residual.lpNorm<Eigen::Infinity>());
    EXPECT_EQ((values(system.tangent()) - tangentElsewhere).lpNorm<Eigen::Infinity>(), 0.0);
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, CondensedNewton,
                         ::testing::Values("lblock_elastic.xml", "lblock_viscoelastic.xml", "tet_bar.xml",
                                           "flexible_pendulum.xml", "double_pendulum.xml", "damped_double_pendulum.xml",
                                           "thermo_visco_elastic.xml", "two_thermo_springs.xml",
                                           "lblock_thermoviscoelastic.xml"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                           const std::string file = info.param;
                           return file.substr(0, file.find('.'));
                         });

}  // namespace
}  // namespace mpx::test
