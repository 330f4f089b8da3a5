#include "engine/linear/cholmod_solver.hpp"

#include <algorithm>
#include <stdexcept>

namespace mpx {

CholmodSolver::CholmodSolver(int size) : lu_(size) {
  cholmod_start(&common_);
  // a supernodal LL^T, which reports a symmetric part that is not positive definite (a
  // simplicial LDL^T would factorise an indefinite one without pivoting)
  common_.supernodal = CHOLMOD_SUPERNODAL;
  rhs_ = cholmod_allocate_dense(size, 1, size, CHOLMOD_REAL, &common_);
}

CholmodSolver::~CholmodSolver() {
  cholmod_free_dense(&rhs_, &common_);
  cholmod_free_dense(&solution_, &common_);
  cholmod_free_dense(&work_, &common_);
  cholmod_free_dense(&errorWork_, &common_);
  cholmod_free_factor(&factor_, &common_);
  cholmod_free_sparse(&symmetric_, &common_);
  cholmod_finish(&common_);
}

const char* CholmodSolver::name() const {
  return notPositiveDefinite_ ? "UMFPACK (the symmetric part was not positive definite)"
                              : "CHOLMOD (the symmetric part, for simplified Newton)";
}

void CholmodSolver::buildSymmetricPattern(const Eigen::SparseMatrix<double>& matrix) {
  const int n = static_cast<int>(matrix.rows());
  // the upper-triangle entries (row <= column) of the pattern of A + A^T, column by column
  std::vector<std::vector<int>> rowsOf(n);
  for (int column = 0; column < n; ++column)
    for (Eigen::SparseMatrix<double>::InnerIterator it(matrix, column); it; ++it) {
      const int row = static_cast<int>(it.row());
      rowsOf[std::max(row, column)].push_back(std::min(row, column));
    }
  std::size_t entries = 0;
  for (auto& rows : rowsOf) {
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    entries += rows.size();
  }
  symmetric_ = cholmod_allocate_sparse(n, n, entries, 1, 1, 1, CHOLMOD_REAL, &common_);
  if (!symmetric_) throw std::runtime_error("CHOLMOD could not allocate the symmetric matrix");
  auto* start = static_cast<int*>(symmetric_->p);
  auto* rowIndex = static_cast<int*>(symmetric_->i);
  start[0] = 0;
  for (int column = 0; column < n; ++column) {
    std::copy(rowsOf[column].begin(), rowsOf[column].end(), rowIndex + start[column]);
    start[column + 1] = start[column] + static_cast<int>(rowsOf[column].size());
  }
  // each entry of A adds to s(min, max): half of a(i, j) and half of a(j, i) off the diagonal
  target_.resize(matrix.nonZeros());
  weight_.resize(matrix.nonZeros());
  for (int column = 0; column < n; ++column)
    for (Eigen::SparseMatrix<double>::InnerIterator it(matrix, column); it; ++it) {
      const int row = static_cast<int>(it.row()), upper = std::max(row, column), lower = std::min(row, column);
      const int* first = rowIndex + start[upper];
      const int* last = rowIndex + start[upper + 1];
      const auto k = static_cast<std::size_t>(&it.value() - matrix.valuePtr());
      target_[k] = static_cast<int>(std::lower_bound(first, last, lower) - rowIndex);
      weight_[k] = row == column ? 1.0 : 0.5;
    }
}

bool CholmodSolver::factorize(const Eigen::SparseMatrix<double>& matrix, bool repivot) {
  if (notPositiveDefinite_) return lu_.factorize(matrix, repivot);
  if (!symmetric_) buildSymmetricPattern(matrix);
  auto* values = static_cast<double*>(symmetric_->x);
  std::fill_n(values, symmetric_->nzmax, 0.0);
  const double* entry = matrix.valuePtr();
  for (std::size_t k = 0; k < target_.size(); ++k) values[target_[k]] += weight_[k] * entry[k];
  if (!factor_) factor_ = cholmod_analyze(symmetric_, &common_);
  if (!factor_) return false;
  cholmod_factorize(symmetric_, factor_, &common_);
  if (common_.status == CHOLMOD_NOT_POSDEF) {
    notPositiveDefinite_ = true;
    return lu_.factorize(matrix, repivot);
  }
  // a warning (a tiny diagonal entry) leaves a usable factor; negative codes are failures
  return common_.status >= CHOLMOD_OK;
}

void CholmodSolver::solve(Eigen::VectorXd& rhs) {
  if (notPositiveDefinite_) return lu_.solve(rhs);
  std::copy_n(rhs.data(), rhs.size(), static_cast<double*>(rhs_->x));
  cholmod_solve2(CHOLMOD_A, factor_, rhs_, nullptr, &solution_, nullptr, &work_, &errorWork_, &common_);
  std::copy_n(static_cast<const double*>(solution_->x), rhs.size(), rhs.data());
}

}  // namespace mpx
