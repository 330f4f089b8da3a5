#pragma once
// Balance checks of thermal-solid runs, shared by the EEM and eem4 tests.
#include "support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace mpx::test {

inline std::size_t firstIndexAfter(const History& h, double t) {
  return static_cast<std::size_t>(std::lower_bound(h.time.begin(), h.time.end(), t - 1e-9) - h.time.begin());
}

// An isolated body from tFree on (after its loads): E, L and J constant to 1e-10 (L against |J|
// over the body's size), S never decreasing and grown over the run.
inline void expectIsolatedBalances(const History& h, const char* label, double tFree = 2.0, double size = 10.0) {
  // a run that stopped early would be judged on its shorter history
  ASSERT_FALSE(h.summary.failed) << label << ": " << h.summary.failure;
  const std::size_t free = firstIndexAfter(h, tFree);
  ASSERT_LT(free + 1, h.energy.size()) << label << ": no step after t = " << tFree;
  double energyDrift = 0.0, momentumDrift = 0.0, angularDrift = 0.0;
  for (std::size_t n = free; n < h.energy.size(); ++n) {
    energyDrift = std::max(energyDrift, std::abs(h.energy[n] - h.energy[free]));
    momentumDrift = std::max(momentumDrift, (h.momentum[n] - h.momentum[free]).norm());
    angularDrift = std::max(angularDrift, (h.angularMomentum[n] - h.angularMomentum[free]).norm());
  }
  std::printf("%s: energy drift %.2e of %.3e, L drift %.2e, J drift %.2e of %.3e\n", label, energyDrift,
              std::abs(h.energy[free]), momentumDrift, angularDrift, h.angularMomentum[free].norm());
  EXPECT_LT(energyDrift, 1e-10 * std::abs(h.energy[free])) << label;
  EXPECT_LT(momentumDrift, 1e-10 * h.angularMomentum[free].norm() / size) << label;
  EXPECT_LT(angularDrift, 1e-10 * h.angularMomentum[free].norm()) << label;
  EXPECT_EQ(firstEntropyDecrease(h), -1) << label;
  EXPECT_GT(h.entropy.back(), h.entropy.front()) << label;
}

// At every step: E' - E = W + Q - D to 1e-10 of the run's largest energy, and the entropy
// production S' - S - S_boundary non-negative (to round-off).
inline void expectStepBalances(const History& h, const char* label) {
  ASSERT_FALSE(h.summary.failed) << label << ": " << h.summary.failure;
  const double scale = largestEnergy(h);
  double worst = 0.0, leastProduction = INFINITY;
  for (std::size_t n = 1; n < h.energy.size(); ++n) {
    const double change = h.energy[n] - h.energy[n - 1] + h.dissipated[n] - h.dissipated[n - 1];
    const double crossed = h.externalWork[n] - h.externalWork[n - 1] + h.boundaryHeat[n] - h.boundaryHeat[n - 1];
    worst = std::max(worst, std::abs(change - crossed));
    const double production = h.entropy[n] - h.entropy[n - 1] - (h.boundaryEntropy[n] - h.boundaryEntropy[n - 1]);
    leastProduction = std::min(leastProduction, production);
  }
  std::printf("%s: worst step energy balance %.2e of %.3e; least production %.3e; heat in %.3e\n", label, worst, scale,
              leastProduction, h.boundaryHeat.back());
  EXPECT_LT(worst, 1e-10 * scale) << label;
  EXPECT_GE(leastProduction, -kEntropyRoundOff * std::abs(h.entropy.back())) << label;
}

}  // namespace mpx::test
