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

// The symmetric change of C = F^T F for dF = e_i g^T (a position column of a cell: one row of
// F moves with a node's shape gradient g): g F_i + F_i^T g^T, without the products by the zeros.
inline Mat3 strainChangeOfRow(const Mat3& F, int i, const Eigen::RowVector3d& g) {
  const Mat3 half = g.transpose() * F.row(i);
  return half + half.transpose();
}

// A linear map of symmetric tensors to symmetric tensors (a material tangent dS[dC]) tabulated
// on the six symmetric unit tensors: a cell's 3 x nodes position columns then apply it as a
// 6 x 6 product instead of evaluating it (an inverse and a logarithm for Neo-Hooke) per column.
class SymmetricTangent {
 public:
  template <class LinearMap>
  explicit SymmetricTangent(const LinearMap& map) {
    for (int k = 0; k < 6; ++k) {
      const auto [i, j] = kComponent[k];
      Mat3 unit = Mat3::Zero();
      unit(i, j) = unit(j, i) = 1.0;
      const Mat3 image = map(unit);
      for (int m = 0; m < 6; ++m) table_(m, k) = image(kComponent[m][0], kComponent[m][1]);
    }
  }
  // dS[dC] for a symmetric dC (a unit tensor k carries dC's component k once)
  Mat3 operator()(const Mat3& dC) const {
    Eigen::Matrix<double, 6, 1> components;
    for (int k = 0; k < 6; ++k) components[k] = dC(kComponent[k][0], kComponent[k][1]);
    const Eigen::Matrix<double, 6, 1> image = table_ * components;
    Mat3 out;
    for (int m = 0; m < 6; ++m) {
      const auto [i, j] = kComponent[m];
      out(i, j) = out(j, i) = image[m];
    }
    return out;
  }

 private:
  Eigen::Matrix<double, 6, 6> table_;
};

}  // namespace mpx::cell
