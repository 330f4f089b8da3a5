#include "engine/linear/umfpack_solver.hpp"

namespace mpx {

UmfpackSolver::UmfpackSolver(int size) : solution_(size), integerWork_(size), realWork_(size) {
  umfpack_di_defaults(control_);
  control_[UMFPACK_ORDERING] = UMFPACK_ORDERING_METIS;
  // No iterative refinement: Newton's own iterations refine the solution against the true
  // residual, and each refinement step costs a product with the matrix and another solve (it
  // took 45 % of a simplified-Newton step of the level-4 L-block, docs/performance.md).
  control_[UMFPACK_IRSTEP] = 0;
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
  return umfpack_di_numeric(colStart, rowIndex, matrix.valuePtr(), symbolic_, &numeric_, control_, info_) == UMFPACK_OK;
}

void UmfpackSolver::solve(Eigen::VectorXd& rhs) {
  // without refinement UMFPACK does not read the matrix
  umfpack_di_wsolve(UMFPACK_A, nullptr, nullptr, nullptr, solution_.data(), rhs.data(), numeric_, control_, info_,
                    integerWork_.data(), realWork_.data());
  rhs.swap(solution_);
}

}  // namespace mpx
