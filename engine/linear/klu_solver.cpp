#include "engine/linear/klu_solver.hpp"

namespace mpx {

namespace {
// Re-pivot when the reciprocal pivot growth of the reused pivots falls below this (a stable
// factorisation has growth of order one; min/max |U_ii| would be the wrong test here: saddle
// points and mixed units make it tiny for perfectly good pivots).
constexpr double kRepivotGrowth = 1e-8;
}  // namespace

KluSolver::KluSolver() { klu_defaults(&common_); }

KluSolver::~KluSolver() {
  if (numeric_) klu_free_numeric(&numeric_, &common_);
  if (symbolic_) klu_free_symbolic(&symbolic_, &common_);
}

bool KluSolver::factorize(const Eigen::SparseMatrix<double>& matrix, bool repivot) {
  // Eigen and KLU store the compressed columns the same way; KLU only reads them
  auto* colStart = const_cast<int*>(matrix.outerIndexPtr());
  auto* rowIndex = const_cast<int*>(matrix.innerIndexPtr());
  auto* values = const_cast<double*>(matrix.valuePtr());
  const int n = static_cast<int>(matrix.rows());

  if (!symbolic_) symbolic_ = klu_analyze(n, colStart, rowIndex, &common_);
  if (!symbolic_) return false;

  // reuse the pivot order while it stays good
  if (numeric_ && !repivot) {
    if (klu_refactor(colStart, rowIndex, values, symbolic_, numeric_, &common_) &&
        klu_rgrowth(colStart, rowIndex, values, symbolic_, numeric_, &common_) && common_.rgrowth > kRepivotGrowth)
      return true;
  }
  if (numeric_) klu_free_numeric(&numeric_, &common_);
  numeric_ = klu_factor(colStart, rowIndex, values, symbolic_, &common_);
  return numeric_ != nullptr && common_.status == KLU_OK;
}

void KluSolver::solve(Eigen::VectorXd& rhs) {
  klu_solve(symbolic_, numeric_, static_cast<int>(rhs.size()), 1, rhs.data(), &common_);
}

}  // namespace mpx
