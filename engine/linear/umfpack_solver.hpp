#pragma once
// Sparse LU with SuiteSparse UMFPACK for large systems (3D solids). The symbolic analysis,
// with a METIS fill-reducing ordering, is done once for the fixed pattern; every
// factorisation pivots afresh (UMFPACK's numeric object is allocated inside the library).
// Solves use preallocated workspace.
#include "engine/linear/sparse_lu.hpp"

#include <umfpack.h>

#include <vector>

namespace mpx {

class UmfpackSolver final : public SparseLu {
 public:
  explicit UmfpackSolver(int size);
  ~UmfpackSolver();
  UmfpackSolver(const UmfpackSolver&) = delete;
  UmfpackSolver& operator=(const UmfpackSolver&) = delete;

  bool factorize(const Eigen::SparseMatrix<double>& matrix, bool repivot) override;
  void solve(Eigen::VectorXd& rhs) override;
  const char* name() const override { return "UMFPACK"; }

 private:
  double control_[UMFPACK_CONTROL];
  double info_[UMFPACK_INFO];
  void* symbolic_ = nullptr;
  void* numeric_ = nullptr;
  Eigen::VectorXd solution_;
  std::vector<int> integerWork_;
  std::vector<double> realWork_;
};

}  // namespace mpx
