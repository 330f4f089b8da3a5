#include "klu_solver.hpp"

namespace mpx {

namespace {
// Re-pivot when the cheap reciprocal pivot-growth estimate falls below this.
constexpr double kRepivotRcond = 1e-12;
}  // namespace

KluSolver::KluSolver() { klu_defaults(&common_); }

KluSolver::~KluSolver() {
  if (numeric_) klu_free_numeric(&numeric_, &common_);
  if (symbolic_) klu_free_symbolic(&symbolic_, &common_);
}

bool KluSolver::factorize(const Eigen::SparseMatrix<double>& matrix) {
  // Eigen and KLU store the compressed columns the same way; KLU only reads them
  auto* colStart = const_cast<int*>(matrix.outerIndexPtr());
  auto* rowIndex = const_cast<int*>(matrix.innerIndexPtr());
  auto* values = const_cast<double*>(matrix.valuePtr());
  const int n = static_cast<int>(matrix.rows());

  if (!symbolic_) symbolic_ = klu_analyze(n, colStart, rowIndex, &common_);
  if (!symbolic_) return false;

  // reuse the pivot order while it stays good
  if (numeric_) {
    if (klu_refactor(colStart, rowIndex, values, symbolic_, numeric_, &common_) &&
        klu_rcond(symbolic_, numeric_, &common_) && common_.rcond > kRepivotRcond)
      return true;
    klu_free_numeric(&numeric_, &common_);
  }
  numeric_ = klu_factor(colStart, rowIndex, values, symbolic_, &common_);
  return numeric_ != nullptr && common_.status == KLU_OK;
}

void KluSolver::solve(Eigen::VectorXd& rhs) {
  klu_solve(symbolic_, numeric_, static_cast<int>(rhs.size()), 1, rhs.data(), &common_);
}

}  // namespace mpx
