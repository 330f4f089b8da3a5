#pragma once
// Static condensation of internal variables: unknowns whose own block of the matrix splits
// into small independent groups (the 6 viscous strains of one quadrature point, the internal
// variable of one Maxwell element; in an eem4 step, those of both stages together) are
// eliminated group by group,
//   x_g = B_g^-1 (b_g - K_gc x_c),   K_cc <- K_cc - K_cg B_g^-1 K_gc,
// before the sparse factorisation. A group couples only to its element's dofs, so the fill
// stays inside the element's block and the factorised system is that of the elastic problem.
#include <Eigen/Dense>
#include <Eigen/Sparse>

#include <vector>

namespace mpx {

class GroupElimination {
 public:
  // Largest group eliminated (a point's 6 viscous strains at two stages), and most kept rows
  // or columns one group may couple to (a hexahedron's 24 momentum rows and positions and 8
  // temperatures at two stages, a joint force's two bodies); beyond either the internal
  // unknowns are left in place.
  static constexpr int kMaxGroup = 12;
  static constexpr int kMaxCoupling = 96;

  // Eliminate the unknowns of the ranges (first, count) of matrices with `pattern` (rows =
  // columns). Returns false, and leaves the system alone, unless their block splits into
  // groups of at most kMaxGroup unknowns.
  struct Range {
    int first, count;
  };
  bool build(const Eigen::SparseMatrix<double>& pattern, const std::vector<Range>& ranges);
  bool active() const { return !groups_.empty(); }

  // The condensed matrix of `matrix` (pattern as built); false if a group's block is singular.
  bool reduce(const Eigen::SparseMatrix<double>& matrix);
  const Eigen::SparseMatrix<double>& reduced() const { return reduced_; }
  // Right-hand side of the condensed system from that of the whole one.
  void reduceRhs(const Eigen::VectorXd& rhs, Eigen::VectorXd& reducedRhs) const;
  // The whole solution from the condensed one (overwrites `solution`, sized like rhs).
  void recover(const Eigen::VectorXd& rhs, const Eigen::VectorXd& reducedSolution, Eigen::VectorXd& solution) const;

 private:
  using Block = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxGroup, kMaxGroup>;
  using GroupVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxGroup, 1>;
  using RowCoupling = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxCoupling, kMaxGroup>;
  using ColumnCoupling = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxGroup, kMaxCoupling>;
  // Entry positions (-1: structurally zero) of one group, row-major within each list.
  struct Group {
    std::vector<int> members;        // unknowns of the whole system
    std::vector<int> blockEntries;   // members x members in the matrix values
    std::vector<int> rows;           // kept rows that see the group
    std::vector<int> rowEntries;     // rows x members
    std::vector<int> columns;        // kept columns the group sees
    std::vector<int> columnEntries;  // members x columns
    std::vector<int> fillEntries;    // rows x columns in the reduced values
  };
  int keptIndex(int i) const { return keptIndex_[i]; }
  static double valueAt(const double* values, int entry) { return entry < 0 ? 0.0 : values[entry]; }

  std::vector<int> keptIndex_;  // of each unknown in the reduced system, -1 where eliminated
  std::vector<Group> groups_;
  std::vector<std::pair<int, int>> directEntries_;  // (matrix entry, reduced entry) of kept pairs
  Eigen::SparseMatrix<double> reduced_;
  const Eigen::SparseMatrix<double>* matrix_ = nullptr;
  std::vector<Eigen::PartialPivLU<Block>> factors_;  // per group, of the last reduce
};

}  // namespace mpx
