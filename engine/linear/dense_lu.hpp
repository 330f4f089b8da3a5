#pragma once
// Dense LU with partial pivoting (Eigen) for the smallest condensed systems, where KLU's
// bookkeeping (pivot reuse checks, scaling, sparse triangular solves) costs more than the
// arithmetic of a dense factorisation (docs/performance.md, "Leaner evaluations, a stage
// predictor and a dense LU for tiny systems"). Storage is allocated once for the system's size.
#include "engine/linear/sparse_lu.hpp"

#include <Eigen/Dense>

namespace mpx {

class DenseLu final : public SparseLu {
 public:
  explicit DenseLu(int size);

  // Pivots afresh every time (the cost of choosing them is negligible at this size).
  bool factorize(const Eigen::SparseMatrix<double>& matrix, bool repivot) override;
  void solve(Eigen::VectorXd& rhs) override;
  const char* name() const override { return "a dense LU"; }

 private:
  Eigen::MatrixXd matrix_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  Eigen::VectorXd solution_;
};

}  // namespace mpx
