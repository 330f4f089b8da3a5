// The component contract (engine/core/component.hpp), checked with a fake component: a linear
// spring between two masses that also writes one bogus tangent entry into a kinematic row.
// What the engine promises: the tangent keeps only the pairs couples() allows (the bogus entry
// is dropped when the component says it never writes kinematic rows), velocity condensation
// stays on for such a component and is reported off, with the reason, for one that claims every
// pair; flows of all components are summed; a state whose measures are not finite stops every
// time loop at that step, naming the component, before the history gets the row.
#include "support.hpp"

#include "models/multibody/inertia.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace mpx::test {
namespace {

constexpr double kStiffness = 3.0;
constexpr double kBogus = 99.0;
constexpr double kExternalPower = 1.5;

// Local dofs: x1 (0-2), x2 (3-5), v1 (6-8), v2 (9-11).
class FakeSpring final : public Component {
 public:
  FakeSpring(bool honestRows, int velocityShift)
      : Component("fake", {0, 1, 2, 3, 4, 5, velocityShift, velocityShift + 1, velocityShift + 2, velocityShift + 3,
                           velocityShift + 4, velocityShift + 5}),
        honestRows_(honestRows) {}

  bool couples(int row, int column, LocalForm form) const override {
    return honestRows_ ? row >= 6 : Component::couples(row, column, form);
  }
  void measure(const double*, Measures&) const override {}
  void eemLocal(const StepArgs& args, Workspace&, LocalSystem& out, Flows& flows) const override {
    write(args.zOld, args.zNew, out);
    flows.externalWork += kExternalPower;
  }
  void rateLocal(const RateArgs& args, Workspace&, LocalSystem& out, Flows& flows) const override {
    write(args.z, args.z, out);
    flows.externalWork += kExternalPower;
  }

 private:
  // momentum rows +-k (x1 - x2) at the midpoint, and the bogus kinematic entry K(x1, v2)
  void write(const double* zOld, const double* zNew, LocalSystem& out) const {
    for (int k = 0; k < 3; ++k) {
      const double stretch = 0.5 * (zOld[k] + zNew[k] - zOld[3 + k] - zNew[3 + k]);
      out.r[6 + k] += kStiffness * stretch;
      out.r[9 + k] -= kStiffness * stretch;
      out.tangent()(6 + k, k) += 0.5 * kStiffness;
      out.tangent()(6 + k, 3 + k) -= 0.5 * kStiffness;
      out.tangent()(9 + k, k) -= 0.5 * kStiffness;
      out.tangent()(9 + k, 3 + k) += 0.5 * kStiffness;
    }
    out.tangent()(0, 9) += kBogus;
  }

  bool honestRows_;
};

std::unique_ptr<Model> twoMasses(bool honestRows, int fakes = 1) {
  const Layout layout({6, 6, 0, 0, 0});
  std::vector<std::unique_ptr<Component>> components;
  for (int m = 0; m < 2; ++m)
    components.push_back(std::make_unique<Inertia>("m" + std::to_string(m), 3 * m, 6 + 3 * m,
                                                   std::vector<InertiaBlock>{{1.0, true}}, Vec3::Zero()));
  for (int f = 0; f < fakes; ++f) components.push_back(std::make_unique<FakeSpring>(honestRows, 6));
  Eigen::VectorXd z = Eigen::VectorXd::Zero(12);
  z.head<3>() << 0.0, 0.0, 0.0;
  z.segment<3>(3) << 1.2, 0.1, 0.0;
  return std::make_unique<Model>(layout, ThermalVariable::Temperature, std::move(components),
                                 std::vector<std::string>{}, z, Eigen::VectorXd::Ones(12));
}

TEST(ComponentContract, TangentKeepsOnlyCoupledPairsAndCondensationStaysOn) {
  const auto model = twoMasses(true);
  Integrator integrator(*model, Scheme::Eem, NewtonSettings{});
  const Eigen::VectorXd z = model->initialState();
  const Eigen::MatrixXd K = Eigen::MatrixXd(integrator.evaluate(z, z, 0.0, 0.1).tangent());
  EXPECT_EQ(K(0, 9), 0.0) << "an entry outside couples() reached the tangent";
  EXPECT_EQ(K(6, 0), 0.5 * kStiffness);  // the spring's own momentum-row entry
  EXPECT_TRUE(integrator.linearSolver().wholeSystemReason().empty());
  EXPECT_EQ(integrator.linearSolver().condensedSize(), 6);  // positions only
}

TEST(ComponentContract, ClaimingKinematicRowsTurnsCondensationOffAndSaysWhy) {
  const auto model = twoMasses(false);
  Integrator integrator(*model, Scheme::Eem, NewtonSettings{});
  const Eigen::VectorXd z = model->initialState();
  const Eigen::MatrixXd K = Eigen::MatrixXd(integrator.evaluate(z, z, 0.0, 0.1).tangent());
  EXPECT_EQ(K(0, 9), kBogus);
  EXPECT_EQ(integrator.linearSolver().condensedSize(), 12);
  const std::string reason = integrator.linearSolver().describe();
  EXPECT_NE(reason.find("solved whole because the kinematic row of position dof "), std::string::npos) << reason;
}

TEST(ComponentContract, FlowsOfAllComponentsAreSummed) {
  const auto model = twoMasses(true, 3);
  Integrator integrator(*model, Scheme::Eem, NewtonSettings{});
  const Eigen::VectorXd z = model->initialState();
  EXPECT_EQ(integrator.evaluate(z, z, 0.0, 0.1).flows().externalWork, 3 * kExternalPower);
  Integrator trapezoidal(*model, Scheme::Trapezoidal, NewtonSettings{});
  EXPECT_DOUBLE_EQ(trapezoidal.evaluate(z, z, 0.0, 0.1).flows().externalWork, 3 * kExternalPower);  // 2 x 1/2
}

// A gauge on a mass's x: it reads the state and adds the energy sqrt(x - kGaugeFloor), which is
// NaN once x < kGaugeFloor, and writes no residual (the state stays acceptable to Newton).
constexpr double kGaugeFloor = 0.45;
class Gauge final : public Component {
 public:
  Gauge() : Component("gauge", {0}) {}
  void measure(const double* z, Measures& out) const override { out.energy += std::sqrt(z[0] - kGaugeFloor); }
  void eemLocal(const StepArgs&, Workspace&, LocalSystem&, Flows&) const override {}
  void rateLocal(const RateArgs&, Workspace&, LocalSystem&, Flows&) const override {}
};

// One free mass moving from x = 1 at -1 m/s: x falls below kGaugeFloor in the step ending at t = 0.6.
std::unique_ptr<Model> gaugedMass() {
  std::vector<std::unique_ptr<Component>> components;
  components.push_back(std::make_unique<Inertia>("m", 0, 3, std::vector<InertiaBlock>{{1.0, true}}, Vec3::Zero()));
  components.push_back(std::make_unique<Gauge>());
  Eigen::VectorXd z = Eigen::VectorXd::Zero(6);
  z[0] = 1.0;
  z[3] = -1.0;
  return std::make_unique<Model>(Layout({3, 3, 0, 0, 0}), ThermalVariable::Temperature, std::move(components),
                                 std::vector<std::string>{}, z, Eigen::VectorXd::Ones(6));
}

TEST(ComponentContract, ANonFiniteMeasureStopsEveryTimeLoopAtItsStepNamingTheComponent) {
  const auto model = gaugedMass();
  for (const char* name : {"eem", "eem-adaptive", "ida"}) {
    SCOPED_TRACE(name);
    MethodParameters parameters;
    parameters.dt = 0.1;
    parameters.tEnd = 2.0;
    parameters.adaptive = std::string(name) == "eem-adaptive";
    double lastTime = -1.0;
    const RunSummary summary =
        runMethod(*model, *methodByName(name), parameters, [&](const StepRecord& record) { lastTime = record.time; });
    ASSERT_TRUE(summary.failed);
    EXPECT_NE(summary.failure.find("measured by gauge is not finite"), std::string::npos) << summary.failure;
    // the history ends at the last finite state: x(t) = 1 - t stays above the floor to t = 0.55
    EXPECT_LE(lastTime, 1.0 - kGaugeFloor + 1e-9);
    std::printf("%s: history ends at t = %.3f\n", name, lastTime);
    EXPECT_GT(lastTime, 0.3);
    if (std::string(name) == "eem") {
      EXPECT_EQ(summary.failedStep, 6);
      EXPECT_NEAR(summary.failedTime, 0.5, 1e-12);
      EXPECT_NEAR(lastTime, 0.5, 1e-12);
    }
  }
}

}  // namespace
}  // namespace mpx::test
