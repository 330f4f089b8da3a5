// Discrete gradients (docs/theory.md section 2) on smooth functions and on the element laws, and
// the laws' own jets and thermodynamics, which the discrete gradients and the tangents rely on.
#include "engine/core/discrete_gradient.hpp"
#include "models/lumped/element_laws.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <tuple>
#include <vector>

namespace mpx {
namespace {

using ScalarFunction = std::function<Jet(const Vec3&)>;

enum class Form { Partitioned, Gonzalez };

const char* formName(Form form) { return form == Form::Partitioned ? "partitioned" : "gonzalez"; }
void PrintTo(Form form, std::ostream* out) { *out << formName(form); }

DiscreteGradient discreteGradient(Form form, const ScalarFunction& f, unsigned mask, const Vec3& a, const Vec3& b,
                                  const Vec3& scale) {
  return form == Form::Partitioned ? partitionedGradient(f, mask, a, b, scale) : gonzalezGradient(f, mask, a, b, scale);
}

// A function of three arguments coupling all of them non-polynomially, so that no discrete
// gradient coincides with the midpoint gradient by accident:
//   F = exp(x/2) cos y + x^2 w + sin(y w) + w^3/3.
Jet smoothJet(const Vec3& arguments) {
  const double x = arguments[0], y = arguments[1], w = arguments[2];
  const double e = std::exp(0.5 * x);
  Jet jet;
  jet.value = e * std::cos(y) + x * x * w + std::sin(y * w) + w * w * w / 3.0;
  jet.grad = Vec3(0.5 * e * std::cos(y) + 2.0 * x * w, -e * std::sin(y) + w * std::cos(y * w),
                  x * x + y * std::cos(y * w) + w * w);
  jet.hess(0, 0) = 0.25 * e * std::cos(y) + 2.0 * w;
  jet.hess(1, 1) = -e * std::cos(y) - w * w * std::sin(y * w);
  jet.hess(2, 2) = -y * y * std::sin(y * w) + 2.0 * w;
  jet.hess(0, 1) = jet.hess(1, 0) = -0.5 * e * std::sin(y);
  jet.hess(0, 2) = jet.hess(2, 0) = 2.0 * x;
  jet.hess(1, 2) = jet.hess(2, 1) = std::cos(y * w) - y * w * std::sin(y * w);
  return jet;
}

// Thermo-elastic material of the scenes; the curvature of C(theta) only in temperature form.
ThermoElasticParameters thermoParameters(double branchStiffness, double stiffnessCurvature) {
  ThermoElasticParameters p;
  p.stiffness = 1.0;
  p.stiffnessSlope = -0.2;
  p.stiffnessCurvature = stiffnessCurvature;
  p.coupling = 0.5;
  p.restLength = 1.0;
  p.heatCapacity = 1.0;
  p.referenceTemperature = 1.0;
  p.branchStiffness = branchStiffness;
  return p;
}

ThermoElasticParameters reservoirParameters() {
  ThermoElasticParameters p;
  p.hasStretch = false;
  p.heatCapacity = 5.0;
  return p;
}

// A scalar function with the active arguments of its discrete gradient and a step a -> b.
// Inactive arguments are parameters: they keep a's value at b.
struct GradientCase {
  std::string name;
  ScalarFunction f;
  unsigned mask;
  Vec3 a, b, scale;
};

void PrintTo(const GradientCase& c, std::ostream* out) { *out << c.name; }

GradientCase makeCase(std::string name, ScalarFunction f, unsigned mask, const Vec3& a, Vec3 b, const Vec3& scale) {
  for (int i = 0; i < 3; ++i)
    if (!(mask >> i & 1u)) b[i] = a[i];
  return {std::move(name), std::move(f), mask, a, b, scale};
}

ScalarFunction energyOf(std::shared_ptr<const ElementLaw> law) {
  return [law](const Vec3& x) { return law->energy(x); };
}
ScalarFunction entropyOf(std::shared_ptr<const ElementLaw> law) {
  return [law](const Vec3& x) { return law->entropy(x); };
}

std::vector<GradientCase> gradientCases() {
  const Vec3 unit = Vec3::Ones();
  const auto hooke = std::make_shared<HookeLaw>(3.0, 1.0, 2.0);
  const auto thermo = std::make_shared<ThermoElasticLaw>(thermoParameters(0.0, 0.05), ThermalVariable::Temperature);
  const auto thermoMaxwell =
      std::make_shared<ThermoElasticLaw>(thermoParameters(2.0, 0.05), ThermalVariable::Temperature);
  const auto thermoEntropy = std::make_shared<ThermoElasticLaw>(thermoParameters(0.0, 0.0), ThermalVariable::Entropy);
  const auto thermoMaxwellEntropy =
      std::make_shared<ThermoElasticLaw>(thermoParameters(2.0, 0.0), ThermalVariable::Entropy);
  const auto reservoir = std::make_shared<ThermoElasticLaw>(reservoirParameters(), ThermalVariable::Temperature);
  const auto reservoirEntropy = std::make_shared<ThermoElasticLaw>(reservoirParameters(), ThermalVariable::Entropy);

  // smooth function points; element arguments (c, s, gamma): a stretched, warm element and a
  // step changing all three, with s a temperature or an entropy
  const Vec3 smoothA(0.3, 0.7, -0.4), smoothB(0.5, 0.55, -0.15);
  const Vec3 temperatureA(2.25, 1.2, 0.1), temperatureB(2.5, 1.35, 0.05);
  const Vec3 entropyA(2.25, 0.3, 0.1), entropyB(2.5, 0.45, 0.05);
  const Vec3 hookeA(2.25, 0.0, 0.1), hookeB(2.0, 0.0, 0.18);
  const Vec3 reservoirA(0.0, 1.2, 0.0), reservoirB(0.0, 1.5, 0.0);
  return {
      makeCase("smooth_first", smoothJet, 0b001u, smoothA, smoothB, unit),
      makeCase("smooth_first_two", smoothJet, 0b011u, smoothA, smoothB, unit),
      makeCase("smooth_first_last", smoothJet, 0b101u, smoothA, smoothB, unit),
      makeCase("smooth_all", smoothJet, 0b111u, smoothA, smoothB, unit),
      makeCase("hooke_branch_energy", energyOf(hooke), 0b101u, hookeA, hookeB, unit),
      makeCase("thermo_temperature_energy", energyOf(thermo), 0b011u, temperatureA, temperatureB, unit),
      makeCase("thermo_temperature_entropy", entropyOf(thermo), 0b011u, temperatureA, temperatureB, unit),
      makeCase("thermo_maxwell_temperature_energy", energyOf(thermoMaxwell), 0b111u, temperatureA, temperatureB, unit),
      makeCase("thermo_maxwell_temperature_entropy", entropyOf(thermoMaxwell), 0b111u, temperatureA, temperatureB,
               unit),
      makeCase("thermo_entropy_energy", energyOf(thermoEntropy), 0b011u, entropyA, entropyB, unit),
      makeCase("thermo_maxwell_entropy_energy", energyOf(thermoMaxwellEntropy), 0b111u, entropyA, entropyB, unit),
      makeCase("reservoir_temperature_entropy", entropyOf(reservoir), 0b010u, reservoirA, reservoirB, unit),
      makeCase("reservoir_entropy_energy", energyOf(reservoirEntropy), 0b010u, reservoirA, reservoirB,
               Vec3(1.0, 5.0, 1.0)),
  };
}

// The active part of a vector: inactive arguments zeroed.
Vec3 activePart(const Vec3& v, unsigned mask) {
  Vec3 out = Vec3::Zero();
  for (int i = 0; i < 3; ++i)
    if (mask >> i & 1u) out[i] = v[i];
  return out;
}

// Central differences of a vector function g of x, one column per argument in `mask` (the
// others zero), with steps relative to the argument's magnitude and scale.
template <class VectorFunction>
auto centralJacobian(const VectorFunction& g, const Vec3& x, const Vec3& scale, unsigned mask) {
  using Column = std::decay_t<decltype(g(x))>;
  Eigen::Matrix<double, Column::RowsAtCompileTime, 3> jacobian;
  jacobian.setZero();
  for (int j = 0; j < 3; ++j) {
    if (!(mask >> j & 1u)) continue;
    const double h = 1e-5 * std::max(std::abs(x[j]), scale[j]);
    Vec3 forward = x, backward = x;
    forward[j] += h;
    backward[j] -= h;
    jacobian.col(j) = (g(forward) - g(backward)) / (2.0 * h);
  }
  return jacobian;
}

// Directionality defect |DF(a, b).(b - a) - (F(b) - F(a))| relative to |F(a)| + |F(b)| + |DF| |b - a|,
// the magnitudes whose round-off it carries.
double relativeDirectionalityDefect(const ScalarFunction& f, const DiscreteGradient& dg, const Vec3& a, const Vec3& b) {
  const double fa = f(a).value, fb = f(b).value;
  const double work = dg.grad.dot(b - a);
  return std::abs(work - (fb - fa)) / (std::abs(fa) + std::abs(fb) + dg.grad.norm() * (b - a).norm());
}

class DiscreteGradientTest : public testing::TestWithParam<std::tuple<GradientCase, Form>> {
 protected:
  const GradientCase& c() const { return std::get<0>(GetParam()); }
  DiscreteGradient at(const Vec3& b) const {
    return discreteGradient(std::get<1>(GetParam()), c().f, c().mask, c().a, b, c().scale);
  }
  // |DF(a, b) - grad F((a + b)/2)|, the distance from the midpoint gradient
  double midpointDeviation(const Vec3& b) const {
    return (at(b).grad - activePart(c().f(0.5 * (c().a + b)).grad, c().mask)).norm();
  }
  // b at relative increment `relative` (of max(|a_i|, scale_i)) from a in every active
  // argument, in the direction of the case's step
  Vec3 endPointAtRelativeIncrement(double relative) const {
    Vec3 b = c().a;
    for (int i = 0; i < 3; ++i)
      if (c().mask >> i & 1u)
        b[i] += std::copysign(relative * std::max(std::abs(c().a[i]), c().scale[i]), c().b[i] - c().a[i]);
    return b;
  }
};

// The defining property: the discrete gradient does exactly the work F(b) - F(a); inactive
// arguments get neither a gradient nor a linearisation.
TEST_P(DiscreteGradientTest, DirectionalityToRoundOff) {
  const DiscreteGradient dg = at(c().b);
  EXPECT_LT(relativeDirectionalityDefect(c().f, dg, c().a, c().b), 1e-13);
  for (int i = 0; i < 3; ++i) {
    if (c().mask >> i & 1u) continue;
    EXPECT_EQ(dg.grad[i], 0.0) << "inactive argument " << i;
    EXPECT_EQ(dg.dGradDb.row(i).norm() + dg.dGradDb.col(i).norm(), 0.0) << "inactive argument " << i;
  }
}

// DF(a, a) is the analytic gradient and its linearisation half the Hessian (the derivative of
// a symmetric discrete gradient at a = b), which is where Newton starts every step.
TEST_P(DiscreteGradientTest, ConsistentAtCoincidentPoints) {
  const Jet exact = c().f(c().a);
  const DiscreteGradient dg = at(c().a);
  const Vec3 grad = activePart(exact.grad, c().mask);
  EXPECT_LE((dg.grad - grad).norm(), 1e-14 * grad.norm());
  Mat3 halfHessian = 0.5 * exact.hess;
  for (int i = 0; i < 3; ++i) {
    if (c().mask >> i & 1u) continue;
    halfHessian.row(i).setZero();
    halfHessian.col(i).setZero();
  }
  EXPECT_LE((dg.dGradDb - halfHessian).norm(), 1e-14 * halfHessian.norm());
}

// Second order: DF(a, a + h d) - grad F(a + h d/2) = O(h^2), slope 2 on a log-log fit.
TEST_P(DiscreteGradientTest, SecondOrderAccurate) {
  const Vec3 direction = c().b - c().a;
  std::vector<double> logH, logError;
  for (double exponent = -1.0; exponent >= -3.0; exponent -= 0.5) {
    const double h = std::pow(10.0, exponent);
    logH.push_back(std::log(h));
    logError.push_back(std::log(midpointDeviation(c().a + h * direction)));
  }
  const Eigen::Map<const Eigen::VectorXd> x(logH.data(), logH.size()), y(logError.data(), logError.size());
  const Eigen::VectorXd xc = x.array() - x.mean(), yc = y.array() - y.mean();
  const double slope = xc.dot(yc) / xc.squaredNorm();
  EXPECT_NEAR(slope, 2.0, 0.1);
}

// Newton's tangent: dGradDb is the derivative of DF(a, b) with respect to b.
TEST_P(DiscreteGradientTest, LinearisationMatchesFiniteDifferences) {
  const Mat3 numeric = centralJacobian([&](const Vec3& b) { return at(b).grad; }, c().b, c().scale, c().mask);
  const Mat3 analytic = at(c().b).dGradDb;
  EXPECT_LE((analytic - numeric).cwiseAbs().maxCoeff(), 1e-6 * analytic.cwiseAbs().maxCoeff())
      << "analytic\n"
      << analytic << "\nfinite differences\n"
      << numeric;
}

// Either side of kQuotientSwitch (relative increments 0.5x and 2x the switch): directionality
// holds to round-off, both branches stay within 1e-8 of the midpoint gradient (the value does
// not jump), and the linearisation changes by 1e-3 at most (it drifts by O(increment) only).
TEST_P(DiscreteGradientTest, ContinuousAcrossQuotientSwitch) {
  const Vec3 below = endPointAtRelativeIncrement(0.5 * kQuotientSwitch);
  const Vec3 above = endPointAtRelativeIncrement(2.0 * kQuotientSwitch);
  const Jet fa = c().f(c().a);
  const double magnitude = std::abs(fa.value) + fa.grad.norm();
  for (const Vec3& b : {below, above}) {
    EXPECT_LT(relativeDirectionalityDefect(c().f, at(b), c().a, b), 1e-14);
    EXPECT_LT(midpointDeviation(b), 1e-8 * magnitude);
  }
  const Mat3 jump = at(above).dGradDb - at(below).dGradDb;
  EXPECT_LE(jump.norm(), 1e-3 * at(below).dGradDb.norm());
}

std::string caseName(const testing::TestParamInfo<DiscreteGradientTest::ParamType>& info) {
  return std::get<0>(info.param).name + "_" + formName(std::get<1>(info.param));
}

INSTANTIATE_TEST_SUITE_P(AllFunctions, DiscreteGradientTest,
                         testing::Combine(testing::ValuesIn(gradientCases()),
                                          testing::Values(Form::Partitioned, Form::Gonzalez)),
                         caseName);

// The jets the discrete gradients and tangents are built from: gradient and Hessian of every
// law (and of the smooth test function) against central differences, at both case points.
TEST(LawJets, GradientAndHessianMatchFiniteDifferences) {
  for (const GradientCase& c : gradientCases()) {
    for (const Vec3& x : {c.a, c.b}) {
      const Jet jet = c.f(x);
      const auto value = [&](const Vec3& y) { return Eigen::Matrix<double, 1, 1>(c.f(y).value); };
      const Vec3 grad = centralJacobian(value, x, c.scale, 0b111u).transpose();
      const Mat3 hess = centralJacobian([&](const Vec3& y) { return c.f(y).grad; }, x, c.scale, 0b111u);
      EXPECT_LE((jet.grad - grad).cwiseAbs().maxCoeff(), 1e-7 * (std::abs(jet.value) + jet.grad.norm()))
          << c.name << " gradient at " << x.transpose() << ": " << jet.grad.transpose() << " vs " << grad.transpose();
      EXPECT_LE((jet.hess - hess).cwiseAbs().maxCoeff(), 1e-7 * (jet.grad.norm() + jet.hess.norm()))
          << c.name << " Hessian at " << x.transpose() << ":\n"
          << jet.hess << "\nvs\n"
          << hess;
      EXPECT_EQ((jet.hess - jet.hess.transpose()).norm(), 0.0) << c.name << " Hessian not symmetric";
    }
  }
}

// Temperature form: e(c, theta, gamma) and eta(c, theta, gamma) come from one free energy,
// so de/dtheta = theta deta/dtheta, also with a curved C(theta) and a Maxwell branch.
TEST(LawThermodynamics, TemperatureFormEnergyAndEntropyShareTheTemperature) {
  for (double branch : {0.0, 2.0}) {
    const ThermoElasticLaw law(thermoParameters(branch, 0.05), ThermalVariable::Temperature);
    for (const Vec3& x : {Vec3(2.25, 1.2, 0.1), Vec3(0.7, 0.6, -0.2), Vec3(1.0, 2.5, 0.0)}) {
      const double theta = x[1];
      const double dEnergy = law.energy(x).grad[1], dEntropy = law.entropy(x).grad[1];
      EXPECT_NEAR(dEnergy, theta * dEntropy, 1e-14 * std::abs(dEnergy)) << "at " << x.transpose();
    }
  }
}

// Entropy form is the same material: at eta = eta(c, theta, gamma) of the temperature form,
// the energy is equal, de/deta = theta, and de/dc, de/dgamma at fixed eta equal the free-energy
// derivatives de/dx - theta deta/dx at fixed theta.
TEST(LawThermodynamics, EntropyFormIsTheTemperatureFormAtEqualEntropy) {
  for (double branch : {0.0, 2.0}) {
    const ThermoElasticLaw byTemperature(thermoParameters(branch, 0.0), ThermalVariable::Temperature);
    const ThermoElasticLaw byEntropy(thermoParameters(branch, 0.0), ThermalVariable::Entropy);
    for (const Vec3& x : {Vec3(2.25, 1.2, 0.1), Vec3(0.7, 0.6, -0.2), Vec3(1.0, 2.5, 0.0)}) {
      const double theta = x[1];
      const Jet energy = byTemperature.energy(x), entropy = byTemperature.entropy(x);
      const Jet energyAtEntropy = byEntropy.energy(Vec3(x[0], entropy.value, x[2]));
      const double magnitude = std::abs(energy.value) + energy.grad.norm() + theta * entropy.grad.norm();
      EXPECT_NEAR(energyAtEntropy.value, energy.value, 1e-14 * magnitude) << "at " << x.transpose();
      EXPECT_NEAR(energyAtEntropy.grad[1], theta, 1e-14 * magnitude) << "at " << x.transpose();
      for (int i : {0, 2})
        EXPECT_NEAR(energyAtEntropy.grad[i], energy.grad[i] - theta * entropy.grad[i], 1e-14 * magnitude)
            << "argument " << i << " at " << x.transpose();
    }
  }
}

// A law that declares its entropy linear is taken at its word: the elements then use the
// entropy's gradient for every discrete and stage gradient. It must be constant with a zero
// Hessian, and both discrete gradients must reduce to it exactly; the temperature form, whose
// entropy is logarithmic in theta, must not declare it.
TEST(LawThermodynamics, ALinearEntropyHasOneGradientThatEveryDiscreteGradientReturns) {
  const std::vector<std::shared_ptr<const ElementLaw>> linear = {
      std::make_shared<HookeLaw>(3.0, 1.0, 2.0),
      std::make_shared<ThermoElasticLaw>(thermoParameters(0.0, 0.0), ThermalVariable::Entropy),
      std::make_shared<ThermoElasticLaw>(thermoParameters(2.0, 0.0), ThermalVariable::Entropy),
      std::make_shared<ThermoElasticLaw>(reservoirParameters(), ThermalVariable::Entropy)};
  const Vec3 a(2.25, 0.3, 0.1), b(2.5, 0.45, 0.05);
  for (const auto& law : linear) {
    ASSERT_TRUE(law->linearEntropy());
    const Jet atA = law->entropy(a), atB = law->entropy(b);
    EXPECT_EQ(atA.grad, atB.grad);
    EXPECT_EQ(atA.hess.norm(), 0.0);
    EXPECT_EQ(atB.value - atA.value, atA.grad.dot(b - a));
    for (Form form : {Form::Partitioned, Form::Gonzalez}) {
      const DiscreteGradient d = discreteGradient(form, entropyOf(law), 0b111u, a, b, Vec3::Ones());
      EXPECT_EQ(d.grad, atA.grad) << formName(form);
      EXPECT_EQ(d.dGradDb.norm(), 0.0) << formName(form);
    }
  }
  EXPECT_FALSE(ThermoElasticLaw(thermoParameters(0.0, 0.0), ThermalVariable::Temperature).linearEntropy());
}

}  // namespace
}  // namespace mpx
