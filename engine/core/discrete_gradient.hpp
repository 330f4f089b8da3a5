#pragma once
// Discrete gradients of scalar functions of up to three scalar arguments, with their
// linearisation with respect to the end point (for Newton's consistent tangent).
//
// Both forms satisfy directionality exactly, DF(a, b) . (b - a) = F(b) - F(a), and are
// symmetric in (a, b), hence consistent and second order (docs/theory.md section 2).
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace mpx {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

// Value, gradient and Hessian of a scalar function of three scalar arguments.
struct Jet {
  double value = 0.0;
  Vec3 grad = Vec3::Zero();
  Mat3 hess = Mat3::Zero();
};

// A discrete (or exact) gradient and its derivative with respect to the end point b.
struct DiscreteGradient {
  Vec3 grad = Vec3::Zero();
  Mat3 dGradDb = Mat3::Zero();
};

// Relative increment h below which a difference quotient is replaced by its midpoint limit.
// Above it the quotient carries round-off eps/h (1e-11) and its derivative eps/h^2 (1e-6),
// which keeps Newton's residual well below its tolerance; below it the midpoint derivative
// breaks directionality by only O(h^3) = 1e-15 relative to the energy.
inline constexpr double kQuotientSwitch = 1e-5;

// True when b - a is too small, relative to the arguments and their scale, to divide by.
inline bool isTinyIncrement(double a, double b, double scale) {
  return std::abs(b - a) <= kQuotientSwitch * std::max({std::abs(a), std::abs(b), scale});
}

// The exact gradient at a point, packaged like a discrete gradient (dGradDb is the Hessian).
inline DiscreteGradient exactGradient(const Jet& jet) { return {jet.grad, jet.hess}; }

// Partitioned (coordinate-increment) discrete gradient averaged over all orderings of the
// active arguments: component i is the weighted mean of difference quotients in argument i
// taken at the corners of the box [a, b] where a subset T of the other arguments already
// sits at b. The weights |T|! (n-1-|T|)! / n! (the Shapley weights) make the average over
// all n! orderings, which is symmetric in (a, b). `mask` selects the active arguments
// (bit i for argument i); inactive ones keep a's value. f maps a Vec3 to a Jet.
template <class Fn>
DiscreteGradient partitionedGradient(const Fn& f, unsigned mask, const Vec3& a, const Vec3& b, const Vec3& scale) {
  // shapleyWeight[n][k]: weight of a subset of size k of the other n-1 arguments
  static constexpr double shapleyWeight[4][3] = {{0, 0, 0}, {1, 0, 0}, {0.5, 0.5, 0}, {1.0 / 3, 1.0 / 6, 1.0 / 3}};
  // bits set in a subset of the three arguments (a table: no popcount instruction is assumed)
  static constexpr int subsetSize[8] = {0, 1, 1, 2, 1, 2, 2, 3};
  const int n = subsetSize[mask & 7u];

  // corners of the box, evaluated lazily: argument j at b when bit j of the subset is set
  Jet corner[8];
  bool evaluated[8] = {};
  auto cornerPoint = [&](unsigned subset) {
    Vec3 p = a;
    for (int j = 0; j < 3; ++j)
      if (subset >> j & 1u) p[j] = b[j];
    return p;
  };
  auto cornerJet = [&](unsigned subset) -> const Jet& {
    if (!evaluated[subset]) {
      corner[subset] = f(cornerPoint(subset));
      evaluated[subset] = true;
    }
    return corner[subset];
  };

  DiscreteGradient out;
  for (int i = 0; i < 3; ++i) {
    if (!(mask >> i & 1u)) continue;
    const unsigned bitI = 1u << i;
    const double delta = b[i] - a[i];
    const bool tiny = isTinyIncrement(a[i], b[i], scale[i]);
    for (unsigned subset = 0; subset < 8; ++subset) {
      if ((subset & ~mask) || (subset & bitI)) continue;
      const double w = shapleyWeight[n][subsetSize[subset]];
      // the 0/0 limit: derivative at the midpoint of the i-th edge, no raw tiny division
      if (tiny) {
        Vec3 mid = cornerPoint(subset);
        mid[i] = 0.5 * (a[i] + b[i]);
        const Jet jm = f(mid);
        out.grad[i] += w * jm.grad[i];
        out.dGradDb(i, i) += w * 0.5 * jm.hess(i, i);
        for (int j = 0; j < 3; ++j)
          if (subset >> j & 1u) out.dGradDb(i, j) += w * jm.hess(i, j);
        continue;
      }
      const Jet& from = cornerJet(subset);
      const Jet& to = cornerJet(subset | bitI);
      const double quotient = (to.value - from.value) / delta;
      out.grad[i] += w * quotient;
      out.dGradDb(i, i) += w * (to.grad[i] - quotient) / delta;
      for (int j = 0; j < 3; ++j)
        if (subset >> j & 1u) out.dGradDb(i, j) += w * (to.grad[j] - from.grad[j]) / delta;
    }
  }
  return out;
}

// Gonzalez (midpoint) discrete gradient with the constant diagonal metric G = diag(1/scale^2):
//   DF = dF(m) + [F(b) - F(a) - dF(m).d] G d / (d.G d),  m = (a+b)/2, d = b - a.
template <class Fn>
DiscreteGradient gonzalezGradient(const Fn& f, unsigned mask, const Vec3& a, const Vec3& b, const Vec3& scale) {
  Vec3 active = Vec3::Zero();
  for (int i = 0; i < 3; ++i)
    if (mask >> i & 1u) active[i] = 1.0;
  const Vec3 d = (b - a).cwiseProduct(active);
  const Vec3 metric = active.cwiseQuotient(scale.cwiseProduct(scale));
  const Vec3 gd = metric.cwiseProduct(d);
  const Mat3 activeBlock = active * active.transpose();

  const Jet mid = f(0.5 * (a + b));
  DiscreteGradient out;
  out.grad = mid.grad.cwiseProduct(active);
  out.dGradDb = 0.5 * mid.hess.cwiseProduct(activeBlock);

  // below the switch the correction is O(|d|) and the quotient would be round-off: drop it
  double relative = 0.0;
  for (int i = 0; i < 3; ++i)
    if (mask >> i & 1u)
      relative = std::max(relative, std::abs(d[i]) / std::max({std::abs(a[i]), std::abs(b[i]), scale[i]}));
  if (relative <= kQuotientSwitch) return out;

  const double dGd = d.dot(gd);
  const Jet from = f(a);
  const Jet to = f(b);
  const double defect = to.value - from.value - out.grad.dot(d);
  const double kappa = defect / dGd;
  out.grad += kappa * gd;
  const Vec3 dDefect = (to.grad - mid.grad - 0.5 * mid.hess * d).cwiseProduct(active);
  const Vec3 dKappa = dDefect / dGd - (2.0 * defect / (dGd * dGd)) * gd;
  out.dGradDb += gd * dKappa.transpose();
  out.dGradDb.diagonal() += kappa * metric;
  return out;
}

// The logarithmic mean (b - a)/ln(b/a) of two positive temperatures and its derivative with
// respect to b: the discrete temperature D_theta e / D_theta eta of a heat capacity with e linear
// and eta logarithmic in theta, for which c (b - a) = mean * c ln(b/a) holds exactly. Near
// b = a the series in u = b/a - 1 (error below 1e-13 relative), never 0/0.
struct LogarithmicMean {
  double value = 0.0;
  double derivative = 0.0;  // d value / d b
};

inline LogarithmicMean logarithmicMean(double a, double b) {
  const double u = b / a - 1.0;
  if (std::abs(u) < 1e-3) return {a * (1.0 + u * (0.5 + u * (-1.0 / 12 + u / 24))), 0.5 + u * (-1.0 / 6 + u / 8)};
  const double logRatio = std::log(b / a), value = (b - a) / logRatio;
  return {value, (1.0 - value / b) / logRatio};
}

}  // namespace mpx
