#pragma once
// Gauss collocation in time (the eem4 step, docs/theory.md section 13): the state is a
// polynomial of degree s over the step through z(t) and the stage values Z_1..Z_s at the
// Gauss-Legendre nodes t + c_l dt, and the rate form holds at each node. It is the continuous
// Galerkin time finite element cG(s) with s-point Gauss quadrature, of order 2s.
#include <array>
#include <cmath>

namespace mpx {

struct CollocationRule {
  static constexpr int kMostStages = 3;
  int stages = 0;
  std::array<double, kMostStages> node{};    // c_l in (0, 1)
  std::array<double, kMostStages> weight{};  // b_l, summing to 1
  // z'(t + c_l dt) = sum_j rate[l][j] Z_j / dt, with Z_0 = z(t)
  std::array<std::array<double, kMostStages + 1>, kMostStages> rate{};
  // z(t + dt) = sum_j end[j] Z_j
  std::array<double, kMostStages + 1> end{};
};

// The s-stage rule (s = 1, 2, 3: orders 2, 4, 6), from the Lagrange basis on {0, c_1..c_s}.
inline CollocationRule gaussCollocation(int stages) {
  CollocationRule rule;
  rule.stages = stages;
  const double r3 = std::sqrt(3.0) / 6.0, r15 = std::sqrt(15.0) / 10.0;
  if (stages == 1) rule.node = {0.5}, rule.weight = {1.0};
  if (stages == 2) rule.node = {0.5 - r3, 0.5 + r3}, rule.weight = {0.5, 0.5};
  if (stages == 3) rule.node = {0.5 - r15, 0.5, 0.5 + r15}, rule.weight = {5.0 / 18, 4.0 / 9, 5.0 / 18};
  // basis point j: 0 for the step's start, l + 1 for stage l
  std::array<double, CollocationRule::kMostStages + 1> point{};
  for (int l = 0; l < stages; ++l) point[l + 1] = rule.node[l];
  auto basis = [&](int j, double x) {
    double value = 1.0;
    for (int m = 0; m <= stages; ++m)
      if (m != j) value *= (x - point[m]) / (point[j] - point[m]);
    return value;
  };
  auto basisSlope = [&](int j, double x) {
    double slope = 0.0;
    for (int skip = 0; skip <= stages; ++skip) {
      if (skip == j) continue;
      double term = 1.0 / (point[j] - point[skip]);
      for (int m = 0; m <= stages; ++m)
        if (m != j && m != skip) term *= (x - point[m]) / (point[j] - point[m]);
      slope += term;
    }
    return slope;
  };
  for (int j = 0; j <= stages; ++j) {
    rule.end[j] = basis(j, 1.0);
    for (int l = 0; l < stages; ++l) rule.rate[l][j] = basisSlope(j, rule.node[l]);
  }
  return rule;
}

}  // namespace mpx
