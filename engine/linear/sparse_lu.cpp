#include "engine/linear/sparse_lu.hpp"

#include "engine/linear/cholmod_solver.hpp"
#include "engine/linear/dense_lu.hpp"
#include "engine/linear/klu_solver.hpp"
#include "engine/linear/umfpack_solver.hpp"

namespace mpx {

std::unique_ptr<SparseLu> makeSparseLu(int size, bool symmetricPart) {
  if (size >= kLargeSystem && symmetricPart) return std::make_unique<CholmodSolver>(size);
  if (size >= kLargeSystem) return std::make_unique<UmfpackSolver>(size);
  if (size <= kSmallSystem) return std::make_unique<DenseLu>(size);
  return std::make_unique<KluSolver>();
}

}  // namespace mpx
