// Redundant constraint conditions (models/multibody/redundant_constraints.hpp, docs/theory.md
// section 6.3): planar closed loops of 3D revolute joints, whose out-of-plane conditions repeat,
// run under the augmented Lagrangian with the redundant conditions found at set-up. Judged against
// an independent reduced-coordinate solution (tests/planar_linkage.hpp) of a crank-rocker
// four-bar and a Watt six-bar (two loops, one degree of freedom): the trajectory converges to it
// at order 2, every condition (the redundant ones too) holds to round-off and E is exact.
#include "planar_linkage.hpp"
#include "support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <string>
#include <vector>

namespace {

using namespace mpx;
using mpx::test::PlanarLinkage;

constexpr double kTEnd = 1.0;
const std::vector<double> kSampleTimes = {0.25, 0.5, 0.75, 1.0};

struct Mechanism {
  const char* scene;
  PlanarLinkage (*reference)();
  std::vector<std::string> bodies;  // in the reference's link order
  std::size_t redundant;            // 6 bodies - 5 joints + rigidity, against the true 1 dof
};

std::ostream& operator<<(std::ostream& os, const Mechanism& m) { return os << m.scene; }

// Angle of body `frame`'s x axis (its bar) in the x-y plane.
double barAngle(const BodyFrame& frame, const Eigen::VectorXd& z) {
  Eigen::Matrix3d directors;
  for (int i = 0; i < 3; ++i) directors.col(i) = z.segment<3>(frame.firstPositionDof + 3 + 3 * i);
  const Eigen::Vector3d bar = directors * frame.directorsToBody * Eigen::Vector3d::UnitX();
  return std::atan2(bar.y(), bar.x());
}

double wrapped(double angle) { return std::remainder(angle, 2.0 * M_PI); }

// Largest distance of the engine's centres (m) and bar angles (rad) from the reference's at the
// sample times.
double largestDeviation(const CompiledScene& scene, const mpx::test::History& h, const Mechanism& m,
                        const std::vector<mpx::test::PlanarSample>& reference) {
  double deviation = 0.0;
  for (const mpx::test::PlanarSample& sample : reference) {
    std::size_t row = 0;
    while (row < h.time.size() && std::abs(h.time[row] - sample.time) > 1e-9) ++row;
    EXPECT_LT(row, h.time.size()) << "no history row at t = " << sample.time;
    if (row == h.time.size()) return INFINITY;
    for (std::size_t link = 0; link < m.bodies.size(); ++link) {
      const auto frame = std::find_if(scene.bodies.begin(), scene.bodies.end(),
                                      [&](const BodyFrame& b) { return b.name == m.bodies[link]; });
      const Eigen::VectorXd& z = h.states[row];
      const Eigen::Vector3d centre = z.segment<3>(frame->firstPositionDof);
      const double angle = barAngle(*frame, z) - barAngle(*frame, h.states[0]);
      deviation = std::max({deviation, (centre.head<2>() - sample.q.segment<2>(3 * link)).norm(), std::abs(centre.z()),
                            std::abs(wrapped(angle - sample.q[3 * link + 2]))});
    }
  }
  return deviation;
}

class RedundantLoopTest : public ::testing::TestWithParam<Mechanism> {
 protected:
  CompiledScene load() const { return loadScene(mpx::test::scenePath(GetParam().scene)); }
  std::vector<mpx::test::PlanarSample> reference() const {
    return GetParam().reference().integrate(0.0, kTEnd, 1e-4, kSampleTimes);
  }
};

// The count of redundant conditions is the spatial mobility's deficit, all of them in the
// joints declared last in each loop
TEST_P(RedundantLoopTest, FindsAsManyRedundantConditionsAsTheLoopsRepeat) {
  const CompiledScene scene = load();
  std::size_t count = 0;
  for (const RedundantConditions& r : scene.redundantConditions) count += r.forms.size();
  EXPECT_EQ(count, GetParam().redundant) << describeRedundancy(scene.redundantConditions);
}

// EEM at dt and dt/2: the error against the reduced-coordinate solution falls at order 2 and is
// below 3e-4 at dt = 2.5e-3 (measured: 1.2e-4 four-bar, 9.2e-6 six-bar); E is exact and every condition, redundant or
// not, holds to round-off at every step
TEST_P(RedundantLoopTest, EemConvergesToTheReducedCoordinateSolution) {
  const CompiledScene scene = load();
  const std::vector<mpx::test::PlanarSample> exact = reference();
  std::vector<double> steps = {5e-3, 2.5e-3}, errors;
  for (double dt : steps) {
    const mpx::test::History h = mpx::test::run(*scene.model, Scheme::Eem, dt, kTEnd);
    ASSERT_FALSE(h.summary.failed) << h.summary.failure;
    EXPECT_LT(mpx::test::maxBalanceDrift(h), 1e-12 * mpx::test::largestEnergy(h));
    double violation = 0.0;
    for (const Eigen::VectorXd& z : h.states) {
      Measures measures;
      scene.model->measure(z, measures);
      violation = std::max(violation, measures.constraintViolation);
    }
    EXPECT_LT(violation, 1e-12) << "dt " << dt;
    errors.push_back(largestDeviation(scene, h, GetParam(), exact));
  }
  EXPECT_NEAR(mpx::test::logLogSlope(steps, errors), 2.0, 0.3) << errors[0] << " " << errors[1];
  EXPECT_LT(errors.back(), 3e-4);
}

// IDA's rate form (GGL) with the redundant multipliers held at zero starts from consistent
// initial values and follows the reference at rtol 1e-10 to 1e-6 (measured: 2.6e-7, 3.4e-7)
TEST_P(RedundantLoopTest, IdaFollowsTheReducedCoordinateSolution) {
  const CompiledScene scene = load();
  const mpx::test::History h = mpx::test::runIda(*scene.model, 1e-10, kTEnd, false, 0.05);
  ASSERT_FALSE(h.summary.failed) << h.summary.failure;
  EXPECT_LT(largestDeviation(scene, h, GetParam(), reference()), 1e-6);
}

INSTANTIATE_TEST_SUITE_P(
    Loops, RedundantLoopTest,
    ::testing::Values(
        Mechanism{"four_bar_revolute.xml", mpx::test::fourBarCrankRocker, {"crank", "coupler", "rocker"}, 3},
        Mechanism{"watt_six_bar.xml", mpx::test::wattSixBar, {"crank", "coupler", "rocker", "coupler2", "rocker2"}, 6}),
    [](const auto& info) { return std::string(info.param.scene).substr(0, 8); });

// A tree has no redundant conditions, nor a loop whose joints repeat none (the universal and
// spherical pair of four_bar_planar.xml)
TEST(RedundantConditions, NoneInATreeOrInALoopWithoutRepeats) {
  for (const char* file : {"double_pendulum.xml", "n_link_chain.xml", "flyball_governor.xml"})
    EXPECT_TRUE(loadScene(mpx::test::scenePath(file)).redundantConditions.empty()) << file;
  EXPECT_TRUE(loadScene(std::string(METRIPLEX_SCENES_DIR) + "/four_bar_planar.xml").redundantConditions.empty());
}

}  // namespace
