#pragma once
// Small tensor helpers shared by a solid cell's step and stage forms (solid_element.cpp,
// solid_element_stages.cpp).
#include "models/fe/material.hpp"

namespace mpx::cell {

// Symmetric tensor components of a viscous strain, in the order of its dofs.
inline constexpr int kComponent[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}};

// The branch stress of a strain A: lambda_v tr(A) I + 2 mu_v A (linear in A).
inline Mat3 branchStressOf(const ViscousBranch& branch, const Mat3& strain) {
  return branch.moduli.lambda * strain.trace() * Mat3::Identity() + 2 * branch.moduli.mu * strain;
}

inline double contract(const Mat3& a, const Mat3& b) { return (a.array() * b.array()).sum(); }

}  // namespace mpx::cell
