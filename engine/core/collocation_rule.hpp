#pragma once
// Gauss collocation in time (the eem4 step, docs/theory.md section 13): the state is a
// polynomial of degree s over the step through z(t) and the stage values Z_1..Z_s at the
// Gauss-Legendre nodes t + c_l dt, and the rate form holds at each node. It is the continuous
// Galerkin time finite element cG(s) with s-point Gauss quadrature, of order 2s.
#include <array>
#include <cassert>
#include <cmath>

namespace mpx {

struct CollocationRule {
  static constexpr int kMostStages = 2;
  // Points of the finer Gauss rule for polynomial integrands along the step (exact to degree 7,
  // enough for a quartic energy's power along the quadratic path of two stages).
  static constexpr int kFinePoints = 4;
  int stages = 0;
  std::array<double, kMostStages> node{};    // c_l in (0, 1)
  std::array<double, kMostStages> weight{};  // b_l, summing to 1
  // z'(t + c_l dt) = sum_j rate[l][j] Z_j / dt, with Z_0 = z(t)
  std::array<std::array<double, kMostStages + 1>, kMostStages> rate{};
  // z(t + dt) = sum_j end[j] Z_j
  std::array<double, kMostStages + 1> end{};
  // the finer rule: at point p (tau_p, weight w_p), z = sum_j fineValue[p][j] Z_j and
  // dz/dtau = sum_j fineRate[p][j] Z_j; fineStage[p][l] is the degree s - 1 Lagrange basis
  // on the stage nodes (the Galerkin test functions, and the shape of a stagewise multiplier)
  std::array<double, kFinePoints> fineNode{}, fineWeight{};
  std::array<std::array<double, kMostStages + 1>, kFinePoints> fineValue{}, fineRate{};
  std::array<std::array<double, kMostStages>, kFinePoints> fineStage{};
};

// The Lagrange basis polynomial of point j among points[0..count-1], at x.
template <std::size_t N>
double lagrangeBasis(const std::array<double, N>& points, int count, int j, double x) {
  double value = 1.0;
  for (int m = 0; m < count; ++m)
    if (m != j) value *= (x - points[m]) / (points[j] - points[m]);
  return value;
}

// The s-stage rule (s = 1, 2: orders 2, 4), from the Lagrange basis on {0, c_1..c_s}.
inline CollocationRule gaussCollocation(int stages) {
  assert(stages >= 1 && stages <= CollocationRule::kMostStages);
  CollocationRule rule;
  rule.stages = stages;
  const double r3 = std::sqrt(3.0) / 6.0;
  if (stages == 1) rule.node = {0.5}, rule.weight = {1.0};
  if (stages == 2) rule.node = {0.5 - r3, 0.5 + r3}, rule.weight = {0.5, 0.5};
  // basis point j: 0 for the step's start, l + 1 for stage l
  std::array<double, CollocationRule::kMostStages + 1> point{};
  for (int l = 0; l < stages; ++l) point[l + 1] = rule.node[l];
  auto basis = [&](int j, double x) { return lagrangeBasis(point, stages + 1, j, x); };
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
  auto stageBasis = [&](int l, double x) { return lagrangeBasis(rule.node, stages, l, x); };
  for (int j = 0; j <= stages; ++j) {
    rule.end[j] = basis(j, 1.0);
    for (int l = 0; l < stages; ++l) rule.rate[l][j] = basisSlope(j, rule.node[l]);
  }
  // 4-point Gauss-Legendre on [0, 1]
  const double inner = std::sqrt(3.0 / 7.0 - 2.0 / 7.0 * std::sqrt(6.0 / 5.0)),
               outer = std::sqrt(3.0 / 7.0 + 2.0 / 7.0 * std::sqrt(6.0 / 5.0));
  const double innerWeight = (18.0 + std::sqrt(30.0)) / 36.0, outerWeight = (18.0 - std::sqrt(30.0)) / 36.0;
  const std::array<double, CollocationRule::kFinePoints> x = {-outer, -inner, inner, outer},
                                                         w = {outerWeight, innerWeight, innerWeight, outerWeight};
  for (int p = 0; p < CollocationRule::kFinePoints; ++p) {
    rule.fineNode[p] = 0.5 * (1.0 + x[p]);
    rule.fineWeight[p] = 0.5 * w[p];
    for (int j = 0; j <= stages; ++j) {
      rule.fineValue[p][j] = basis(j, rule.fineNode[p]);
      rule.fineRate[p][j] = basisSlope(j, rule.fineNode[p]);
    }
    for (int l = 0; l < stages; ++l) rule.fineStage[p][l] = stageBasis(l, rule.fineNode[p]);
  }
  return rule;
}

}  // namespace mpx
