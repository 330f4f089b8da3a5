#pragma once
// Algorithmic stress S~ = 2 D_C W(C0, C1) of a hyperelastic law: Gonzalez discrete derivative of W with respect to C
// in the Frobenius metric (docs/theory.md sections 2.3 and 8.2),
//   S~ = S(Cm) + 2 [W(C1) - W(C0) - S(Cm):dC/2] dC / (dC:dC),  Cm = (C0 + C1)/2, dC = C1 - C0,
// so that S~:(C1 - C0)/2 = W(C1) - W(C0) exactly (directionality); symmetric in (C0, C1), hence second order. Below
// a relative increment |dC| <= 1e-8 max(|C0|, |C1|, 1) (Frobenius norms) it is S(Cm); W(C1) - W(C0)
// comes from the material's cancellation-free energyDifference. Also its
// derivative with respect to C1 for Newton's consistent tangent. Allocation-free: fixed-size matrices only.
#include "models/fe/material.hpp"

namespace mpx {

// Relative |dC| below which S~ is the midpoint stress. The energy difference is free of
// cancellation, so the quotient's round-off is eps |S| at any |dC| and its derivative's
// eps |S| / |dC|; below 1e-8 the midpoint stress misses directionality by O(|dC|^2) = 1e-16.
// (A switch at 1e-5 let Newton toggle between two stresses 1e-10 apart and stall.)
inline constexpr double kStressQuotientSwitch = 1e-8;

class DiscreteStress {
 public:
  // Keeps a pointer to material, which must outlive this object. Without `withIncrement` (a
  // residual-only evaluation) the stress alone: increment() must not be called.
  DiscreteStress(const HyperelasticMaterial& material, const Mat3& C0, const Mat3& C1, bool withIncrement = true);
  // S~
  const Mat3& stress() const { return stress_; }
  // dS~/dC1 [H] for a symmetric direction H
  Mat3 increment(const Mat3& H) const;

 private:
  const HyperelasticMaterial* material_;
  Mat3 midpoint_;                       // Cm
  Mat3 delta_;                          // dC
  Mat3 stress_;                         // S~
  Mat3 defectGradient_ = Mat3::Zero();  // G: derivative of the quotient's numerator N with respect to C1 (if asked)
  double squaredDelta_;                 // D = dC:dC
  double kappa_ = 0.0;                  // N / D
  bool tiny_;                           // below the quotient switch
};

}  // namespace mpx
