#include "models/fe/discrete_stress.hpp"

#include <algorithm>
#include <cmath>

namespace mpx {

DiscreteStress::DiscreteStress(const HyperelasticMaterial& material, const Mat3& C0, const Mat3& C1, bool withIncrement)
    : material_(&material),
      midpoint_(0.5 * (C0 + C1)),
      delta_(C1 - C0),
      stress_(material.stress(midpoint_)),
      squaredDelta_(delta_.squaredNorm()),
      tiny_(std::sqrt(squaredDelta_) <= kStressQuotientSwitch * std::max({C0.norm(), C1.norm(), 1.0})) {
  // below the switch the quotient would divide round-off by a tiny |dC|^2: keep the midpoint stress
  if (tiny_) return;

  // the Gonzalez correction along dC restores directionality; G uses A:dS[B] = B:dS[A] of hyperelastic tangents
  const double defect = material.energyDifference(C0, delta_) - 0.5 * stress_.cwiseProduct(delta_).sum();
  kappa_ = defect / squaredDelta_;
  // the numerator's gradient serves the increment only (a stress and a tangent evaluation)
  if (withIncrement)
    defectGradient_ = 0.5 * (material.stress(C1) - stress_) - 0.25 * material.stressIncrement(midpoint_, delta_);
  stress_ += 2.0 * kappa_ * delta_;
}

Mat3 DiscreteStress::increment(const Mat3& H) const {
  // Cm moves by H/2
  Mat3 out = 0.5 * material_->stressIncrement(midpoint_, H);
  if (tiny_) return out;

  // kappa = N/D varies through N (by G:H) and through D (by 2 dC:H)
  const double kappaIncrement =
      (defectGradient_.cwiseProduct(H).sum() - 2.0 * kappa_ * delta_.cwiseProduct(H).sum()) / squaredDelta_;
  out += 2.0 * kappaIncrement * delta_ + 2.0 * kappa_ * H;
  return out;
}

}  // namespace mpx
