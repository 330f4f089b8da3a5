#pragma once
// Sparse LU with SuiteSparse KLU for the Newton tangent. The pattern is fixed for a run: the
// symbolic analysis is done once, the first numeric factorisation chooses pivots, and later
// factorisations reuse them through klu_refactor, which allocates nothing. When the reused
// pivots become poor (reciprocal pivot growth below a threshold), or the caller asks, KLU
// pivots afresh.
#include "engine/linear/sparse_lu.hpp"

#include <klu.h>

namespace mpx {

class KluSolver final : public SparseLu {
 public:
  KluSolver();
  ~KluSolver();
  KluSolver(const KluSolver&) = delete;
  KluSolver& operator=(const KluSolver&) = delete;

  // Reuses the last pivots unless `repivot`.
  bool factorize(const Eigen::SparseMatrix<double>& matrix, bool repivot) override;
  void solve(Eigen::VectorXd& rhs) override;
  const char* name() const override { return "KLU"; }

 private:
  klu_common common_;
  klu_symbolic* symbolic_ = nullptr;
  klu_numeric* numeric_ = nullptr;
};

}  // namespace mpx
