#include "engine/linear/umfpack_solver.hpp"

namespace mpx {

UmfpackSolver::UmfpackSolver(int size)
    : solution_(size), integerWork_(size), realWork_(5 * static_cast<std::size_t>(size)) {
  umfpack_di_defaults(control_);
  control_[UMFPACK_ORDERING] = UMFPACK_ORDERING_METIS;
}

UmfpackSolver::~UmfpackSolver() {
  if (numeric_) umfpack_di_free_numeric(&numeric_);
  if (symbolic_) umfpack_di_free_symbolic(&symbolic_);
}

bool UmfpackSolver::factorize(const Eigen::SparseMatrix<double>& matrix, bool) {
  const int n = static_cast<int>(matrix.rows());
  const int* colStart = matrix.outerIndexPtr();
  const int* rowIndex = matrix.innerIndexPtr();
  if (!symbolic_ &&
      umfpack_di_symbolic(n, n, colStart, rowIndex, matrix.valuePtr(), &symbolic_, control_, info_) != UMFPACK_OK)
    return false;
  if (numeric_) umfpack_di_free_numeric(&numeric_);
  matrix_ = &matrix;
  return umfpack_di_numeric(colStart, rowIndex, matrix.valuePtr(), symbolic_, &numeric_, control_, info_) == UMFPACK_OK;
}

void UmfpackSolver::solve(Eigen::VectorXd& rhs) {
  umfpack_di_wsolve(UMFPACK_A, matrix_->outerIndexPtr(), matrix_->innerIndexPtr(), matrix_->valuePtr(),
                    solution_.data(), rhs.data(), numeric_, control_, info_, integerWork_.data(), realWork_.data());
  rhs.swap(solution_);
}

}  // namespace mpx
