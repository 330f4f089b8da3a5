// Finite-strain material laws (stress and tangent against finite differences of the energy, the small-strain limit)
// and the Gonzalez discrete stress: directionality, second-order consistency, symmetry and its linearisation.
#include "engine/core/discrete_gradient.hpp"
#include "models/fe/discrete_stress.hpp"
#include "models/fe/material.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <ostream>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>

namespace mpx {
namespace {

// Lame constants of the L-block's elastic solid (docs/theory.md section 11.3: E = 2.26115e3, nu = 0.395469).
const LameParameters kLame = LameParameters::fromYoung(2.26115e3, 0.395469);

// VolumeLogarithm is the thermoelastic coupling 3 beta K ln J (with the thermal L-block's beta =
// 2.233e-4 and K = lambda + 2 mu/3 = 5209 + 2 997.5/3), not an elastic energy: its stress at C = I
// is 3 beta K I, and near it 3 beta K (I - 2 eps).
constexpr double kCoupling = 3 * 2.233e-4 * (5209 + 2 * 997.5 / 3.0);
enum class Law { SaintVenantKirchhoff, NeoHooke, VolumeLogarithm };

void PrintTo(Law law, std::ostream* out) {
  *out << (law == Law::NeoHooke          ? "NeoHooke"
           : law == Law::VolumeLogarithm ? "VolumeLogarithm"
                                         : "SaintVenantKirchhoff");
}

std::unique_ptr<HyperelasticMaterial> makeMaterial(Law law) {
  if (law == Law::NeoHooke) return std::make_unique<NeoHooke>(kLame);
  if (law == Law::VolumeLogarithm) return std::make_unique<VolumeLogarithm>(kCoupling);
  return std::make_unique<SaintVenantKirchhoff>(kLame);
}

// Reproducible random matrices.
class RandomMatrices {
 public:
  explicit RandomMatrices(unsigned seed) : engine_(seed) {}

  // entries uniform in [-1, 1]
  Mat3 uniform() {
    Mat3 m;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) m(i, j) = unit_(engine_);
    return m;
  }

  Mat3 symmetric() {
    const Mat3 m = uniform();
    return 0.5 * (m + m.transpose());
  }

  // a deformation gradient F = I + 0.3 random with det F > 0
  Mat3 deformation() { return perturbed(Mat3::Identity(), 0.3); }

  // F + amplitude random, redrawn until its determinant is positive
  Mat3 perturbed(const Mat3& F, double amplitude) {
    for (;;) {
      const Mat3 G = F + amplitude * uniform();
      if (G.determinant() > 0.0) return G;
    }
  }

 private:
  std::mt19937 engine_;
  std::uniform_real_distribution<double> unit_{-1.0, 1.0};
};

Mat3 cauchyGreen(const Mat3& F) { return F.transpose() * F; }

double relativeError(const Mat3& approximation, const Mat3& exact) {
  return (approximation - exact).norm() / exact.norm();
}

// Gradient G of f with respect to a symmetric X in the Frobenius metric (df = G:dX for symmetric dX), by central
// differences: moving X_ij and X_ji together by h changes f by 2 G_ij h off the diagonal and by G_ii h on it.
template <class Fn>
Mat3 symmetricGradient(const Fn& f, const Mat3& X, double h) {
  Mat3 gradient;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      Mat3 step = Mat3::Zero();
      step(i, j) = step(j, i) = h;
      const double slope = (f(X + step) - f(X - step)) / (2.0 * h);
      gradient(i, j) = i == j ? slope : 0.5 * slope;
    }
  return gradient;
}

// Central difference of a matrix-valued g along the direction H.
template <class Fn>
Mat3 directionalDifference(const Fn& g, const Mat3& X, const Mat3& H, double h) {
  return (g(X + h * H) - g(X - h * H)) / (2.0 * h);
}

TEST(LameParameters, FromYoungMatchesHandValues) {
  // mu = E / (2 (1 + nu)) = 2261.15 / 2.790938, lambda = E nu / ((1 + nu)(1 - 2 nu)) = 894.21473 / 0.29173954
  EXPECT_NEAR(kLame.mu, 810.175647040529, 1e-9);
  EXPECT_NEAR(kLame.lambda, 3065.11324831362, 1e-8);
}

TEST(LameParameters, RejectsInvalidConstantsNamingWhich) {
  auto messageOf = [](double young, double poisson) -> std::string {
    try {
      LameParameters::fromYoung(young, poisson);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  for (double poisson : {0.5, 0.7, -1.0, -1.5, std::nan("")})
    EXPECT_NE(messageOf(1.0, poisson).find("Poisson"), std::string::npos) << "nu = " << poisson;
  for (double young : {0.0, -2.0, std::nan("")})
    EXPECT_NE(messageOf(young, 0.3).find("Young"), std::string::npos) << "E = " << young;
}

class HyperelasticLaw : public ::testing::TestWithParam<Law> {};

TEST_P(HyperelasticLaw, StressIsTwiceTheEnergyGradient) {
  const auto material = makeMaterial(GetParam());
  RandomMatrices random(11);
  for (int sample = 0; sample < 5; ++sample) {
    const Mat3 C = cauchyGreen(random.deformation());
    const Mat3 fd = 2.0 * symmetricGradient([&](const Mat3& X) { return material->energy(X); }, C, 1e-5);
    EXPECT_LT(relativeError(fd, material->stress(C)), 1e-7) << "C =\n" << C;
  }
}

TEST_P(HyperelasticLaw, StressIncrementIsTheStressDerivative) {
  const auto material = makeMaterial(GetParam());
  RandomMatrices random(12);
  for (int sample = 0; sample < 5; ++sample) {
    const Mat3 C = cauchyGreen(random.deformation());
    const Mat3 H = random.symmetric();
    const Mat3 fd = directionalDifference([&](const Mat3& X) { return material->stress(X); }, C, H, 1e-5);
    EXPECT_LT(relativeError(fd, material->stressIncrement(C, H)), 1e-7) << "C =\n" << C;
  }
}

// Elastic laws are stress-free at C = I; the coupling law has the stress 3 beta K I there. All
// have zero energy there.
TEST_P(HyperelasticLaw, ReferenceConfigurationHasItsKnownStress) {
  const auto material = makeMaterial(GetParam());
  const Mat3 expected = GetParam() == Law::VolumeLogarithm ? Mat3(kCoupling * Mat3::Identity()) : Mat3::Zero();
  EXPECT_LT((material->stress(Mat3::Identity()) - expected).norm(), 1e-12 * kLame.mu);
  EXPECT_NEAR(material->energy(Mat3::Identity()), 0.0, 1e-12 * kLame.mu);
}

TEST_P(HyperelasticLaw, TangentIsSymmetric) {
  const auto material = makeMaterial(GetParam());
  RandomMatrices random(13);
  for (int sample = 0; sample < 5; ++sample) {
    const Mat3 C = cauchyGreen(random.deformation());
    const Mat3 A = random.symmetric(), B = random.symmetric();
    const Mat3 dSofA = material->stressIncrement(C, A), dSofB = material->stressIncrement(C, B);
    const double ab = A.cwiseProduct(dSofB).sum(), ba = B.cwiseProduct(dSofA).sum();
    EXPECT_LE(std::abs(ab - ba), 1e-12 * A.norm() * dSofB.norm());
  }
}

// C = I + 2 eps with |eps| = 1e-6: the linear elastic stress lambda tr(eps) I + 2 mu eps (the
// coupling law: 3 beta K (I - 2 eps)), up to O(eps) relative.
TEST_P(HyperelasticLaw, SmallStrainLimitIsLinear) {
  const auto material = makeMaterial(GetParam());
  RandomMatrices random(14);
  const Mat3 shape = random.symmetric();
  const Mat3 eps = 1e-6 * shape / shape.norm();
  const Mat3 linear = GetParam() == Law::VolumeLogarithm
                          ? Mat3(kCoupling * (Mat3::Identity() - 2.0 * eps))
                          : Mat3(kLame.lambda * eps.trace() * Mat3::Identity() + 2.0 * kLame.mu * eps);
  EXPECT_LT(relativeError(material->stress(Mat3::Identity() + 2.0 * eps), linear), 1e-5);
}

INSTANTIATE_TEST_SUITE_P(Laws, HyperelasticLaw,
                         ::testing::Values(Law::SaintVenantKirchhoff, Law::NeoHooke, Law::VolumeLogarithm));

TEST(NeoHooke, InvertedOrCollapsedStrainIsNaN) {
  const NeoHooke material(kLame);
  const Mat3 inverted = Eigen::Vector3d(2.0, 1.0, -0.5).asDiagonal(), collapsed = Eigen::Vector3d(1, 1, 0).asDiagonal();
  for (const Mat3& C : {inverted, collapsed}) {
    EXPECT_TRUE(std::isnan(material.energy(C))) << C;
    EXPECT_TRUE(material.stress(C).array().isNaN().all()) << C;
  }
}

TEST(ViscousBranch, StressIsTheEnergyGradientInStrainAndMinusInViscousStrain) {
  const ViscousBranch branch{LameParameters::fromYoung(500.0, 0.3), 2.0};
  RandomMatrices random(15);
  for (int sample = 0; sample < 3; ++sample) {
    const Mat3 C = cauchyGreen(random.deformation());
    const Mat3 Gamma = 0.1 * random.symmetric();
    const Mat3 S = branch.stress(C, Gamma);
    const Mat3 dPsidC = symmetricGradient([&](const Mat3& X) { return branch.energy(X, Gamma); }, C, 1e-5);
    const Mat3 dPsidGamma = symmetricGradient([&](const Mat3& X) { return branch.energy(C, X); }, Gamma, 1e-5);
    EXPECT_LT(relativeError(2.0 * dPsidC, S), 1e-7);
    EXPECT_LT(relativeError(-dPsidGamma, S), 1e-7);
  }
}

// A pair (C0, C1) whose deformations differ by `amplitude` random (1: independent deformations).
std::pair<Mat3, Mat3> strainPair(RandomMatrices& random, double amplitude) {
  const Mat3 F0 = random.deformation();
  const Mat3 F1 = amplitude >= 1.0 ? random.deformation() : random.perturbed(F0, amplitude);
  return {cauchyGreen(F0), cauchyGreen(F1)};
}

class GonzalezStress : public ::testing::TestWithParam<Law> {};

TEST_P(GonzalezStress, WorkEqualsEnergyChange) {
  const auto material = makeMaterial(GetParam());
  RandomMatrices random(21);
  for (double amplitude : {1.0, 0.3, 1e-2, 1e-4}) {
    const auto [C0, C1] = strainPair(random, amplitude);
    const DiscreteStress discrete(*material, C0, C1);
    const double W0 = material->energy(C0), W1 = material->energy(C1);
    const double work = 0.5 * discrete.stress().cwiseProduct(C1 - C0).sum();
    const double scale = std::abs(W0) + std::abs(W1) + discrete.stress().norm() * (C1 - C0).norm();
    EXPECT_LE(std::abs(work - (W1 - W0)), 1e-13 * scale) << "amplitude " << amplitude;
  }
}

TEST_P(GonzalezStress, IsSymmetricInItsEndPoints) {
  const auto material = makeMaterial(GetParam());
  RandomMatrices random(22);
  for (double amplitude : {1.0, 1e-2}) {
    const auto [C0, C1] = strainPair(random, amplitude);
    const Mat3 forward = DiscreteStress(*material, C0, C1).stress();
    const Mat3 backward = DiscreteStress(*material, C1, C0).stress();
    EXPECT_LE((forward - backward).norm(), 1e-15 * forward.norm()) << "amplitude " << amplitude;
  }
}

// dS~/dC1 against central differences of S~ in C1, for increments above the switch (down to |dC| ~ 1e-6) and
// |dC| ~ 1e-9 below it.
TEST_P(GonzalezStress, IncrementIsTheDerivativeInTheEndPoint) {
  const auto material = makeMaterial(GetParam());
  RandomMatrices random(23);
  struct Case {
    double amplitude, step;
    bool belowSwitch;
  };
  for (const Case& c :
       {Case{1.0, 1e-5, false}, Case{1e-2, 1e-5, false}, Case{1e-6, 1e-7, false}, Case{1e-9, 1e-9, true}}) {
    const auto [C0, C1] = strainPair(random, c.amplitude);
    ASSERT_EQ((C1 - C0).norm() <= kStressQuotientSwitch * std::max(C0.norm(), C1.norm()), c.belowSwitch);
    const Mat3 H = random.symmetric();
    const auto stressAt = [&, start = C0](const Mat3& end) { return DiscreteStress(*material, start, end).stress(); };
    const Mat3 fd = directionalDifference(stressAt, C1, H, c.step);
    const Mat3 exact = DiscreteStress(*material, C0, C1).increment(H);
    EXPECT_LT(relativeError(fd, exact), 1e-6) << "amplitude " << c.amplitude << ", |dC| " << (C1 - C0).norm();
  }
}

// The energy difference is free of cancellation: at |dC| = 1e-7 (above the switch) the Gonzalez correction stays
// at its O(|dC|^2) size instead of round-off eps |W| / |dC|, and it matches W(C1) - W(C0) for a large increment.
TEST_P(GonzalezStress, EnergyDifferenceHasNoCancellation) {
  const auto material = makeMaterial(GetParam());
  RandomMatrices random(29);
  const auto [C0, C1] = strainPair(random, 1e-7);
  const Mat3 correction = DiscreteStress(*material, C0, C1).stress() - material->stress(0.5 * (C0 + C1));
  const double relative = correction.norm() / material->stress(0.5 * (C0 + C1)).norm();
  std::printf("|dC| = %.1e: |S~ - S(Cm)| / |S| = %.2e\n", (C1 - C0).norm(), relative);
  EXPECT_LT(relative, 1e-12);
  const auto [D0, D1] = strainPair(random, 1.0);
  const double direct = material->energy(D1) - material->energy(D0);
  EXPECT_NEAR(material->energyDifference(D0, D1 - D0), direct, 1e-12 * std::abs(material->energy(D1)));
}

INSTANTIATE_TEST_SUITE_P(Laws, GonzalezStress,
                         ::testing::Values(Law::SaintVenantKirchhoff, Law::NeoHooke, Law::VolumeLogarithm));

// |S~ - S(Cm)| = O(|dC|^2) about a fixed midpoint: each halving of dC divides the gap by about 4.
TEST(GonzalezStress, DeviatesFromTheMidpointStressAtSecondOrder) {
  const NeoHooke material(kLame);
  RandomMatrices random(24);
  const Mat3 Cm = cauchyGreen(random.deformation());
  const Mat3 shape = random.symmetric();
  const Mat3 direction = 0.2 * shape / shape.norm();
  double previous = 0.0;
  std::printf("NeoHooke |S~ - S(Cm)|:");
  for (int halving = 0; halving <= 3; ++halving) {
    const Mat3 dC = std::ldexp(1.0, -halving) * direction;
    const double gap = (DiscreteStress(material, Cm - 0.5 * dC, Cm + 0.5 * dC).stress() - material.stress(Cm)).norm();
    std::printf(" %.3e", gap);
    if (halving > 0) {
      const double order = std::log2(previous / gap);
      std::printf(" (order %.4f)", order);
      EXPECT_GT(order, 1.9);
      EXPECT_LT(order, 2.1);
    }
    previous = gap;
  }
  std::printf("\n");
}

// A quadratic energy's midpoint rule is exact: no correction beyond round-off.
TEST(GonzalezStress, IsTheMidpointStressForSaintVenantKirchhoff) {
  const SaintVenantKirchhoff material(kLame);
  RandomMatrices random(25);
  for (int sample = 0; sample < 3; ++sample) {
    const auto [C0, C1] = strainPair(random, 1.0);
    const Mat3 midpointStress = material.stress(0.5 * (C0 + C1));
    EXPECT_LE((DiscreteStress(material, C0, C1).stress() - midpointStress).norm(), 1e-13 * midpointStress.norm());
  }
}

}  // namespace
}  // namespace mpx
