#pragma once
// Finite-difference checks of tangents shared by the tests: central differences of a residual
// and the worst row mismatch against an analytic tangent, entries of different units weighed
// by the dofs' magnitudes.
#include "engine/core/model.hpp"

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include <functional>
#include <random>

namespace mpx::test {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// A fixed pseudo-random vector: entries +-[0.5, 1] times `magnitude`, never near zero.
inline VectorXd randomIsh(const VectorXd& magnitude, unsigned seed) {
  std::mt19937 generator(seed);
  std::uniform_real_distribution<double> size(0.5, 1.0);
  std::bernoulli_distribution negative(0.5);
  VectorXd out(magnitude.size());
  for (Eigen::Index i = 0; i < out.size(); ++i)
    out[i] = (negative(generator) ? -1.0 : 1.0) * size(generator) * magnitude[i];
  return out;
}

// Typical magnitude of each dof at z: |z_i| plus the model's scale.
inline VectorXd magnitudeAt(const Model& model, const VectorXd& z) { return z.cwiseAbs() + model.dofScale(); }

using ResidualFunction = std::function<VectorXd(const VectorXd&)>;

// Central differences of `residual` at x, column j with step relativeStep * magnitude_j.
inline MatrixXd centralDifferences(const ResidualFunction& residual, const VectorXd& x, const VectorXd& magnitude,
                                   double relativeStep) {
  MatrixXd jacobian(x.size(), x.size());
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    const double h = relativeStep * magnitude[j];
    VectorXd forward = x, backward = x;
    forward[j] += h;
    backward[j] -= h;
    jacobian.col(j) = (residual(forward) - residual(backward)) / (2.0 * h);
  }
  return jacobian;
}

// Each row's largest mismatch relative to the row's largest term, with columns weighted by
// the dof magnitudes so that entries of different units compare alike; the worst row wins.
struct Mismatch {
  double relative = 0.0;
  Eigen::Index row = 0, col = 0;
};

inline Mismatch worstRowMismatch(const MatrixXd& analytic, const MatrixXd& numeric, const VectorXd& magnitude) {
  const MatrixXd weight = VectorXd::Ones(analytic.rows()) * magnitude.transpose();
  const MatrixXd error = (analytic - numeric).cwiseAbs().cwiseProduct(weight);
  const MatrixXd size = analytic.cwiseAbs().cwiseMax(numeric.cwiseAbs()).cwiseProduct(weight);
  Mismatch worst;
  for (Eigen::Index i = 0; i < analytic.rows(); ++i) {
    const double rowSize = size.row(i).maxCoeff();
    if (rowSize == 0.0) continue;
    Eigen::Index col = 0;
    const double relative = error.row(i).maxCoeff(&col) / rowSize;
    if (relative > worst.relative) worst = {relative, i, col};
  }
  return worst;
}

inline void expectTangentMatches(const Model& model, const MatrixXd& analytic, const MatrixXd& numeric,
                                 const VectorXd& magnitude, double tolerance) {
  const Mismatch worst = worstRowMismatch(analytic, numeric, magnitude);
  // a system of several stages (eem4) repeats the layout per stage
  const Layout& layout = model.layout();
  const int n = layout.total();
  EXPECT_LT(worst.relative, tolerance) << "row " << worst.row << " (" << blockName(layout.blockOf(worst.row % n))
                                       << "), column " << worst.col << " (" << blockName(layout.blockOf(worst.col % n))
                                       << "): tangent " << analytic(worst.row, worst.col) << ", finite differences "
                                       << numeric(worst.row, worst.col);
}

}  // namespace mpx::test
