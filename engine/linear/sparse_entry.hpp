#pragma once
// Where an entry of a compressed-column matrix lives in its value array, for the scatter maps
// that let fixed-pattern matrices be filled without searching in the step loop.
#include <Eigen/Sparse>

#include <algorithm>

namespace mpx {

// Position of (row, column) in the values of `matrix`, or -1 if it is not in the pattern.
inline int findEntry(const Eigen::SparseMatrix<double>& matrix, int row, int column) {
  const int* begin = matrix.innerIndexPtr() + matrix.outerIndexPtr()[column];
  const int* end = matrix.innerIndexPtr() + matrix.outerIndexPtr()[column + 1];
  const int* it = std::lower_bound(begin, end, row);
  return it != end && *it == row ? static_cast<int>(it - matrix.innerIndexPtr()) : -1;
}

}  // namespace mpx
