#pragma once
// A symmetric approximation for simplified Newton on large systems: the symmetric part
// (A + A^T)/2 of the matrix, factorised by SuiteSparse CHOLMOD (supernodal Cholesky, about half
// the time of UMFPACK's LU on 3D solids: docs/performance.md). Simplified Newton judges its
// iterates on the true residual, so an approximate matrix changes how fast Newton contracts,
// never what it converges to. Where the symmetric part is not positive definite, this solver
// factorises the matrix itself with UMFPACK from then on.
#include "engine/linear/umfpack_solver.hpp"

#include <cholmod.h>

#include <vector>

namespace mpx {

class CholmodSolver final : public SparseLu {
 public:
  explicit CholmodSolver(int size);
  ~CholmodSolver();
  CholmodSolver(const CholmodSolver&) = delete;
  CholmodSolver& operator=(const CholmodSolver&) = delete;

  bool factorize(const Eigen::SparseMatrix<double>& matrix, bool repivot) override;
  void solve(Eigen::VectorXd& rhs) override;
  const char* name() const override;
  bool approximates() const override { return !notPositiveDefinite_; }

 private:
  // The upper triangle of the symmetric part's pattern, and where each entry of the matrix
  // adds to it, from the first matrix (the pattern is fixed for a run).
  void buildSymmetricPattern(const Eigen::SparseMatrix<double>& matrix);

  cholmod_common common_;
  cholmod_sparse* symmetric_ = nullptr;
  cholmod_factor* factor_ = nullptr;
  cholmod_dense* rhs_ = nullptr;
  // cholmod_solve2's solution and workspace, allocated by its first call and reused
  cholmod_dense *solution_ = nullptr, *work_ = nullptr, *errorWork_ = nullptr;
  std::vector<int> target_;     // per matrix entry: its place in symmetric_
  std::vector<double> weight_;  // 1 on the diagonal, 1/2 off it
  bool notPositiveDefinite_ = false;
  UmfpackSolver lu_;  // once the symmetric part is not positive definite
};

}  // namespace mpx
