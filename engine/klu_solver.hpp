#pragma once
// Sparse LU with SuiteSparse KLU for the Newton tangent. The pattern is fixed for a run: the
// symbolic analysis is done once, the first numeric factorisation chooses pivots, and later
// factorisations reuse them through klu_refactor, which allocates nothing. When the reused
// pivots become poor (reciprocal pivot growth below a threshold), or the caller asks, KLU
// pivots afresh.
#include <Eigen/Sparse>
#include <klu.h>

namespace mpx {

class KluSolver {
 public:
  KluSolver();
  ~KluSolver();
  KluSolver(const KluSolver&) = delete;
  KluSolver& operator=(const KluSolver&) = delete;

  // Factorise a compressed column-major matrix whose pattern never changes between calls,
  // reusing the last pivots unless `repivot`. Returns false if the matrix is singular.
  bool factorize(const Eigen::SparseMatrix<double>& matrix, bool repivot = false);
  // Overwrite rhs with the solution of A x = rhs for the last factorised A.
  void solve(Eigen::VectorXd& rhs);

 private:
  klu_common common_;
  klu_symbolic* symbolic_ = nullptr;
  klu_numeric* numeric_ = nullptr;
};

}  // namespace mpx
