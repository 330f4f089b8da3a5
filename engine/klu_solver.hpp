#pragma once
// Sparse LU with SuiteSparse KLU for the Newton tangent. The pattern is fixed for a run: the
// symbolic analysis is done once, the first numeric factorisation chooses pivots, and later
// factorisations reuse them through klu_refactor, which allocates nothing. When the reused
// pivots become poor (reciprocal condition estimate below a threshold) KLU re-pivots.
#include <Eigen/Sparse>
#include <klu.h>

namespace mpx {

class KluSolver {
 public:
  KluSolver();
  ~KluSolver();
  KluSolver(const KluSolver&) = delete;
  KluSolver& operator=(const KluSolver&) = delete;

  // Factorise a compressed column-major matrix whose pattern never changes between calls.
  // Returns false if the matrix is numerically singular.
  bool factorize(const Eigen::SparseMatrix<double>& matrix);
  // Overwrite rhs with the solution of A x = rhs for the last factorised A.
  void solve(Eigen::VectorXd& rhs);

 private:
  klu_common common_;
  klu_symbolic* symbolic_ = nullptr;
  klu_numeric* numeric_ = nullptr;
};

}  // namespace mpx
