#include "engine/linear/dense_lu.hpp"

#include <cmath>

namespace mpx {

DenseLu::DenseLu(int size) : matrix_(size, size), lu_(size), solution_(size) {}

bool DenseLu::factorize(const Eigen::SparseMatrix<double>& matrix, bool) {
  matrix_.setZero();
  for (int column = 0; column < matrix.outerSize(); ++column)
    for (Eigen::SparseMatrix<double>::InnerIterator entry(matrix, column); entry; ++entry)
      matrix_(entry.row(), column) = entry.value();
  lu_.compute(matrix_);
  // partial pivoting leaves a zero on the diagonal of U only for a singular matrix
  const auto diagonal = lu_.matrixLU().diagonal().cwiseAbs();
  return diagonal.minCoeff() > 0.0 && std::isfinite(diagonal.maxCoeff());
}

void DenseLu::solve(Eigen::VectorXd& rhs) {
  solution_ = lu_.solve(rhs);
  rhs.swap(solution_);
}

}  // namespace mpx
