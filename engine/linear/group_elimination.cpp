#include "engine/linear/group_elimination.hpp"

#include "engine/linear/sparse_entry.hpp"

#include <algorithm>
#include <numeric>

namespace mpx {

namespace {
using SparseMatrix = Eigen::SparseMatrix<double>;

// Union-find root with path halving.
int rootOf(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}
}  // namespace

bool GroupElimination::build(const SparseMatrix& pattern, const std::vector<Range>& ranges) {
  keptIndex_.clear();
  groups_.clear();
  directEntries_.clear();
  factors_.clear();
  const int n = static_cast<int>(pattern.rows());
  // slot of each eliminated unknown among them (-1: kept)
  std::vector<int> slot(n, -1), members;
  for (const Range& range : ranges)
    for (int i = range.first; i < range.first + range.count; ++i) {
      slot[i] = static_cast<int>(members.size());
      members.push_back(i);
    }
  const int count = static_cast<int>(members.size());
  if (count == 0) return false;
  auto eliminated = [&](int i) { return slot[i] >= 0; };

  // groups: connected sets of the eliminated unknowns' own block
  std::vector<int> parent(count);
  std::iota(parent.begin(), parent.end(), 0);
  for (int column : members)
    for (SparseMatrix::InnerIterator it(pattern, column); it; ++it)
      if (eliminated(static_cast<int>(it.row()))) parent[rootOf(parent, slot[it.row()])] = rootOf(parent, slot[column]);
  std::vector<int> groupOf(count, -1);
  std::vector<Group> groups;
  for (int i = 0; i < count; ++i) {
    int& group = groupOf[rootOf(parent, i)];
    if (group < 0) {
      group = static_cast<int>(groups.size());
      groups.emplace_back();
    }
    groups[group].members.push_back(members[i]);
    if (groups[group].members.size() > static_cast<std::size_t>(kMaxGroup)) return false;
  }

  // each group's coupling rows and columns among the kept unknowns
  std::vector<std::vector<int>> rowsOf(groups.size()), columnsOf(groups.size());
  for (int column = 0; column < n; ++column)
    for (SparseMatrix::InnerIterator it(pattern, column); it; ++it) {
      const int row = static_cast<int>(it.row());
      if (eliminated(column) && !eliminated(row)) rowsOf[groupOf[rootOf(parent, slot[column])]].push_back(row);
      if (eliminated(row) && !eliminated(column)) columnsOf[groupOf[rootOf(parent, slot[row])]].push_back(column);
    }
  keptIndex_.assign(n, -1);
  for (int i = 0, kept = 0; i < n; ++i)
    if (!eliminated(i)) keptIndex_[i] = kept++;
  std::vector<Eigen::Triplet<double>> entries;
  for (int column = 0; column < n; ++column)
    for (SparseMatrix::InnerIterator it(pattern, column); it; ++it)
      if (!eliminated(column) && !eliminated(static_cast<int>(it.row())))
        entries.emplace_back(keptIndex(static_cast<int>(it.row())), keptIndex(column), 0.0);
  for (std::size_t g = 0; g < groups.size(); ++g) {
    for (auto* list : {&rowsOf[g], &columnsOf[g]}) {
      std::sort(list->begin(), list->end());
      list->erase(std::unique(list->begin(), list->end()), list->end());
      if (list->size() > static_cast<std::size_t>(kMaxCoupling)) {
        keptIndex_.clear();
        return false;
      }
    }
    for (int row : rowsOf[g])
      for (int column : columnsOf[g]) entries.emplace_back(keptIndex(row), keptIndex(column), 0.0);
  }
  reduced_.resize(n - count, n - count);
  reduced_.setFromTriplets(entries.begin(), entries.end());
  reduced_.makeCompressed();

  // entry positions of everything the numeric phase reads and writes
  for (int column = 0; column < n; ++column)
    for (SparseMatrix::InnerIterator it(pattern, column); it; ++it)
      if (!eliminated(column) && !eliminated(static_cast<int>(it.row())))
        directEntries_.emplace_back(static_cast<int>(&it.value() - pattern.valuePtr()),
                                    findEntry(reduced_, keptIndex(static_cast<int>(it.row())), keptIndex(column)));
  for (std::size_t g = 0; g < groups.size(); ++g) {
    Group& group = groups[g];
    group.rows = rowsOf[g];
    group.columns = columnsOf[g];
    for (int a : group.members)
      for (int b : group.members) group.blockEntries.push_back(findEntry(pattern, a, b));
    for (int row : group.rows)
      for (int m : group.members) group.rowEntries.push_back(findEntry(pattern, row, m));
    for (int m : group.members)
      for (int column : group.columns) group.columnEntries.push_back(findEntry(pattern, m, column));
    for (int row : group.rows)
      for (int column : group.columns)
        group.fillEntries.push_back(findEntry(reduced_, keptIndex(row), keptIndex(column)));
  }
  groups_ = std::move(groups);
  factors_.assign(groups_.size(), Eigen::PartialPivLU<Block>(kMaxGroup));
  return true;
}

bool GroupElimination::reduce(const SparseMatrix& matrix) {
  matrix_ = &matrix;
  const double* k = matrix.valuePtr();
  double* out = reduced_.valuePtr();
  std::fill_n(out, reduced_.nonZeros(), 0.0);
  for (const auto& [entry, reducedEntry] : directEntries_) out[reducedEntry] += k[entry];
  // K_cc -= K_cg (B^-1 K_gc) with dense blocks of fixed capacity (no allocation)
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    const Group& group = groups_[g];
    const int s = static_cast<int>(group.members.size());
    const int rows = static_cast<int>(group.rows.size()), columns = static_cast<int>(group.columns.size());
    Block block(s, s);
    for (int a = 0; a < s; ++a)
      for (int b = 0; b < s; ++b) block(a, b) = valueAt(k, group.blockEntries[a * s + b]);
    factors_[g].compute(block);
    if (!(std::abs(factors_[g].determinant()) > 0.0)) return false;
    ColumnCoupling columnCoupling(s, columns);
    for (int m = 0; m < s; ++m)
      for (int c = 0; c < columns; ++c) columnCoupling(m, c) = valueAt(k, group.columnEntries[m * columns + c]);
    RowCoupling rowCoupling(rows, s);
    for (int r = 0; r < rows; ++r)
      for (int m = 0; m < s; ++m) rowCoupling(r, m) = valueAt(k, group.rowEntries[r * s + m]);
    const ColumnCoupling solved = factors_[g].solve(columnCoupling);
    for (int c = 0; c < columns; ++c)
      for (int r = 0; r < rows; ++r) out[group.fillEntries[r * columns + c]] -= rowCoupling.row(r).dot(solved.col(c));
  }
  return true;
}

void GroupElimination::reduceRhs(const Eigen::VectorXd& rhs, Eigen::VectorXd& reducedRhs) const {
  for (Eigen::Index i = 0; i < rhs.size(); ++i)
    if (keptIndex_[i] >= 0) reducedRhs[keptIndex_[i]] = rhs[i];
  const double* k = matrix_->valuePtr();
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    const Group& group = groups_[g];
    const int s = static_cast<int>(group.members.size());
    GroupVector own(s);
    for (int m = 0; m < s; ++m) own[m] = rhs[group.members[m]];
    const GroupVector x = factors_[g].solve(own);
    for (std::size_t r = 0; r < group.rows.size(); ++r)
      for (int m = 0; m < s; ++m)
        reducedRhs[keptIndex(group.rows[r])] -= valueAt(k, group.rowEntries[r * s + m]) * x[m];
  }
}

void GroupElimination::recover(const Eigen::VectorXd& rhs, const Eigen::VectorXd& reducedSolution,
                               Eigen::VectorXd& solution) const {
  for (Eigen::Index i = 0; i < rhs.size(); ++i)
    if (keptIndex_[i] >= 0) solution[i] = reducedSolution[keptIndex_[i]];
  const double* k = matrix_->valuePtr();
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    const Group& group = groups_[g];
    const int s = static_cast<int>(group.members.size()), columns = static_cast<int>(group.columns.size());
    GroupVector own(s);
    for (int m = 0; m < s; ++m) {
      own[m] = rhs[group.members[m]];
      for (int c = 0; c < columns; ++c)
        own[m] -= valueAt(k, group.columnEntries[m * columns + c]) * solution[group.columns[c]];
    }
    const GroupVector x = factors_[g].solve(own);
    for (int m = 0; m < s; ++m) solution[group.members[m]] = x[m];
  }
}

}  // namespace mpx
