#pragma once
// A sparse LU factorisation of a matrix whose pattern is fixed for a run: the symbolic
// analysis is done on the first call, later calls only refactorise the values.
#include <Eigen/Sparse>

#include <memory>

namespace mpx {

class SparseLu {
 public:
  virtual ~SparseLu() = default;
  // Factorise a compressed column-major matrix with the pattern of earlier calls; `repivot`
  // asks for fresh pivots where a solver reuses them. Returns false if the matrix is singular.
  virtual bool factorize(const Eigen::SparseMatrix<double>& matrix, bool repivot) = 0;
  // Overwrite rhs with the solution of A x = rhs for the last factorised A.
  virtual void solve(Eigen::VectorXd& rhs) = 0;
  // The factorisation's name for run summaries ("KLU", ...).
  virtual const char* name() const = 0;
  // True where what is factorised approximates the matrix (its symmetric part): Newton then
  // contracts linearly even with a fresh factorisation.
  virtual bool approximates() const { return false; }
};

// Systems of at least this many unknowns go to UMFPACK, of at most kSmallSystem to a dense LU.
inline constexpr int kLargeSystem = 3000;
inline constexpr int kSmallSystem = 32;

// A dense LU for systems of up to kSmallSystem unknowns (docs/performance.md: 5-7 % less per
// step than KLU at 7-16 unknowns; KLU is cheaper at the 64-190 unknowns of the multibody scenes
// once their patterns hold only the entries their forms reach, for full and simplified Newton
// and mostly for IDA); KLU (pivot reuse, no allocation) for small systems such as multibody and
// thermal networks; UMFPACK with a fill-reducing ordering for the large systems of 3D solids,
// where KLU is 20-60 times slower. With `symmetricPart`, a large system gets CHOLMOD on its
// symmetric part, an approximation for simplified Newton (cholmod_solver.hpp).
std::unique_ptr<SparseLu> makeSparseLu(int size, bool symmetricPart = false);

}  // namespace mpx
