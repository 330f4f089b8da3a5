#pragma once
// The energy-consistent gradient of a scalar function psi of up to three arguments along the
// stage polynomial of an eem4 step (docs/theory.md section 13.2). At stage l it is
//   D psi_l = grad psi(a_l) + mu G a'_l,
//   mu = [psi(a_end) - psi(a_0) - sum_j b_j grad psi(a_j) . a'_j] / sum_j b_j a'_j . G a'_j,
// with a'_j = da/dtau at stage j (tau = (t - t_n) / dt) and the diagonal metric G = 1/scale^2.
// The Gauss sum of D psi . a' is then psi(a_end) - psi(a_0) (exactly but for a floor that only
// acts where the arguments barely move, kStagePathFloor). The correction is the
// quadrature error, O(dt^5) for two stages, divided by O(dt^2): it leaves the order 4 intact.
#include "engine/core/collocation_rule.hpp"
#include "engine/core/component.hpp"
#include "engine/core/discrete_gradient.hpp"

#include <cmath>

namespace mpx {

// A gradient over the arguments and the derivative of each entry over a component's local dofs.
struct GradientRows {
  Vec3 grad = Vec3::Zero();
  LocalRow d[3];
};

// The arguments of one component along the stage polynomial, for the tangent block of stage
// `column`: at each stage j the arguments a_j, their tau-rates a'_j, the rows of da_j/dZ_j and
// of da'_j/dZ_column over the local dofs; a_0 at the start and a_end with d a_end/dz_end.
struct StagePath {
  int column = 0;
  Vec3 start = Vec3::Zero(), end = Vec3::Zero();
  LocalRow endRows[3];
  Vec3 value[CollocationRule::kMostStages], rate[CollocationRule::kMostStages];
  LocalRow rows[CollocationRule::kMostStages][3], rateRows[CollocationRule::kMostStages][3];
};

// The floor of mu's denominator: N + k^2 / (N + k) for N = sum_j b_j a'_j . G a'_j. The defect
// carries the round-off of psi(a_end) - psi(a_0), eps |psi|, which mu = defect / N would amplify
// without bound where the arguments barely move; with the floor it reaches the residual as at
// most eps / sqrt(k) (1e-11 relative) and the tangent as eps / k (1e-6). Where the arguments
// move the floor is N (1 + (k / N)^2): the Gauss sum misses psi's change by (k / N)^2 of the
// defect (itself the O(dt^5) quadrature error), 1e-4 of it even at relative argument changes
// of 1e-5 per step.
inline constexpr double kStagePathFloor = 1e-10;

// A norm N with the floor: N + k^2 / (N + k), and its derivative with respect to N (k: this
// floor, or a smaller one where the defect's round-off is in proportion to the motion).
struct FlooredNorm {
  double value, slope;
};
inline FlooredNorm flooredNorm(double norm, double floor = kStagePathFloor) {
  const double floorRatio = floor / (norm + floor);
  return {norm + floor * floorRatio, 1.0 - floorRatio * floorRatio};
}

// What D psi needs of psi along a path for every stage and column: the metric G, psi's jets at
// the stages and the end, and mu = defect / floored norm with the floor's slope.
struct StageJets {
  Vec3 metric = Vec3::Zero();
  Jet end;
  Jet stage[CollocationRule::kMostStages];
  double defect = 0.0, norm = 1.0, normSlope = 1.0, mu = 0.0;
};

// psi's stage jets along `path`; f maps a Vec3 to a Jet, `mask` selects the active arguments.
template <class Fn>
StageJets stageJets(const Fn& f, unsigned mask, const Vec3& scale, const CollocationRule& rule, const StagePath& path) {
  StageJets jets;
  for (int i = 0; i < 3; ++i)
    if (mask >> i & 1u) jets.metric[i] = 1.0 / (scale[i] * scale[i]);
  jets.end = f(path.end);
  double defect = jets.end.value - f(path.start).value, norm = 0.0;
  for (int j = 0; j < rule.stages; ++j) {
    jets.stage[j] = f(path.value[j]);
    defect -= rule.weight[j] * jets.stage[j].grad.dot(path.rate[j]);
    norm += rule.weight[j] * path.rate[j].dot(jets.metric.cwiseProduct(path.rate[j]));
  }
  const FlooredNorm floored = flooredNorm(norm);
  jets.defect = defect;
  jets.norm = floored.value;
  jets.normSlope = floored.slope;
  jets.mu = defect / floored.value;
  return jets;
}

// D psi at stage `stage` from psi's stage jets, and its derivative with respect to stage
// path.column's values.
inline GradientRows consistentGradient(const StageJets& jets, const CollocationRule& rule, const StagePath& path,
                                       int stage) {
  const int n = static_cast<int>(path.endRows[0].size()), s = rule.stages, k = path.column;
  auto alongRows = [&](const Vec3& coefficients, const LocalRow(&rows)[3]) -> LocalRow {
    return coefficients[0] * rows[0] + coefficients[1] * rows[1] + coefficients[2] * rows[2];
  };
  const Vec3& metric = jets.metric;
  GradientRows out;
  out.grad = jets.stage[stage].grad;
  for (int i = 0; i < 3; ++i)
    out.d[i] = stage == k ? alongRows(jets.stage[stage].hess.row(i).transpose(), path.rows[stage]) : LocalRow::Zero(n);
  // mu's derivative, from those of the defect and of the floored norm
  const double mu = jets.mu;
  LocalRow dDefect = rule.end[k + 1] * alongRows(jets.end.grad, path.endRows);
  LocalRow dNorm = LocalRow::Zero(n);
  for (int j = 0; j < s; ++j) {
    if (j == k) dDefect -= rule.weight[j] * alongRows(jets.stage[j].hess * path.rate[j], path.rows[j]);
    dDefect -= rule.weight[j] * alongRows(jets.stage[j].grad, path.rateRows[j]);
    dNorm += (2.0 * rule.weight[j]) * alongRows(metric.cwiseProduct(path.rate[j]), path.rateRows[j]);
  }
  const LocalRow dMu = (dDefect - (mu * jets.normSlope) * dNorm) / jets.norm;
  const Vec3 direction = metric.cwiseProduct(path.rate[stage]);
  out.grad += mu * direction;
  for (int i = 0; i < 3; ++i) out.d[i] += direction[i] * dMu + (mu * metric[i]) * path.rateRows[stage][i];
  return out;
}

// The same from psi itself: f maps a Vec3 to a Jet, `mask` selects the active arguments.
template <class Fn>
GradientRows consistentGradient(const Fn& f, unsigned mask, const Vec3& scale, const CollocationRule& rule,
                                const StagePath& path, int stage) {
  return consistentGradient(stageJets(f, mask, scale, rule, path), rule, path, stage);
}

}  // namespace mpx

namespace mpx {

// The stage gradient D psi_l of a function of one dof along that dof's stage polynomial (the
// formula above for one argument), and its derivative with respect to the dof's value at stage
// args.column.
struct ScalarStageGradient {
  double value = 0.0;
  double slope = 0.0;
};

// psi(x) as its value and first two derivatives.
struct ScalarJet {
  double value, slope, curvature;
};

// psiJet(x) returns psi at x as a ScalarJet, psiChange(x0, x1) psi(x1) - psi(x0) without
// cancellation (mu divides the defect's round-off by the rates' norm); `scale` is the dof's
// scale in the floor of that norm.
template <class Jet1, class Change>
ScalarStageGradient scalarStageGradient(const Jet1& psiJet, const Change& psiChange, double scale,
                                        const StageArgs& args, int dof) {
  const CollocationRule& rule = *args.rule;
  const int s = rule.stages, l = args.stage, k = args.column;
  const double metric = 1.0 / (scale * scale);
  double rate[CollocationRule::kMostStages];
  ScalarJet jet[CollocationRule::kMostStages];
  double defect = psiChange(args.zOld[dof], args.zEnd[dof]), norm = 0.0;
  for (int j = 0; j < s; ++j) {
    rate[j] = args.dt * args.stageRate[j][dof];
    jet[j] = psiJet(args.stageState[j][dof]);
    defect -= rule.weight[j] * jet[j].slope * rate[j];
    norm += rule.weight[j] * metric * rate[j] * rate[j];
  }
  // derivatives in the column stage's value: x_j moves on its own stage, x'_j by rate[j][k + 1]
  double dDefect = rule.end[k + 1] * psiJet(args.zEnd[dof]).slope, dNorm = 0.0;
  for (int j = 0; j < s; ++j) {
    if (j == k) dDefect -= rule.weight[j] * jet[j].curvature * rate[j];
    dDefect -= rule.weight[j] * jet[j].slope * rule.rate[j][k + 1];
    dNorm += 2.0 * rule.weight[j] * metric * rate[j] * rule.rate[j][k + 1];
  }
  const FlooredNorm floored = flooredNorm(norm);
  const double mu = defect / floored.value;
  const double dMu = (dDefect - mu * floored.slope * dNorm) / floored.value;
  return {jet[l].slope + mu * metric * rate[l],
          (l == k ? jet[l].curvature : 0.0) + dMu * metric * rate[l] + mu * metric * rule.rate[l][k + 1]};
}

// The temperature the heat rows of a dof holding a temperature theta are weighted with at stage
// args.stage: T_l = 1 / D(ln theta)_l, so that sum_l b_l theta'_l / T_l = ln theta(1) - ln theta(0)
// (the stage form of the logarithmic mean). The floor's scale is the step's start temperature.
// A non-positive value (no admissible temperature) is returned as it is: callers reject it.
inline ScalarStageGradient stageTemperature(const StageArgs& args, int dof) {
  auto logarithm = [](double theta) { return ScalarJet{std::log(theta), 1.0 / theta, -1.0 / (theta * theta)}; };
  auto logarithmChange = [](double theta0, double theta1) { return std::log1p((theta1 - theta0) / theta0); };
  const ScalarStageGradient inverse = scalarStageGradient(logarithm, logarithmChange, args.zOld[dof], args, dof);
  const double T = 1.0 / inverse.value;
  return {T, -T * T * inverse.slope};
}

}  // namespace mpx
