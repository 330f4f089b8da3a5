#include "engine/linear/condensed_solver.hpp"

#include "engine/linear/sparse_entry.hpp"

#include <algorithm>

namespace mpx {

namespace {
using SparseMatrix = Eigen::SparseMatrix<double>;
}  // namespace

CondensedSolver::CondensedSolver(const Layout& layout, const SparseMatrix& pattern) : pattern_(&pattern) {
  // positions come first in the layout, velocities right after, dof for dof
  const bool paired = layout.has(Block::Position) && layout.size(Block::Position) == layout.size(Block::Velocity) &&
                      layout.offset(Block::Position) == 0;
  velocities_ = paired ? layout.size(Block::Velocity) : 0;
  if (velocities_ > 0 && !buildCondensation(pattern)) velocities_ = 0;
  reducedRhs_.resize(pattern.rows() - velocities_);
  // internal variables, numbered as in the velocity-condensed system
  const SparseMatrix& stage = velocities_ > 0 ? reduced_ : pattern;
  internal_.build(stage, layout.offset(Block::Internal) - velocities_, layout.size(Block::Internal));
  internalRhs_.resize(internal_.active() ? internal_.reduced().rows() : 0);
  internalSolution_.resize(stage.rows());
  lu_ = makeSparseLu(static_cast<int>(factorised().rows()));
}

bool CondensedSolver::buildCondensation(const SparseMatrix& pattern) {
  const int n = static_cast<int>(pattern.rows()), nv = velocities_;
  auto isPosition = [&](int dof) { return dof < nv; };
  auto isVelocity = [&](int dof) { return dof >= nv && dof < 2 * nv; };

  // kinematic rows: their entries in kept columns, and the single velocity entry d_i
  kinematicRows_.assign(nv, {});
  pivotEntry_.assign(nv, -1);
  for (int column = 0; column < n; ++column)
    for (SparseMatrix::InnerIterator it(pattern, column); it; ++it) {
      const int row = static_cast<int>(it.row());
      if (!isPosition(row)) continue;
      const int entry = static_cast<int>(&it.value() - pattern.valuePtr());
      if (!isVelocity(column))
        kinematicRows_[row].push_back({column, entry});
      else if (column - nv == row)
        pivotEntry_[row] = entry;
      else {
        wholeSystemReason_ = "the kinematic row of position dof " + std::to_string(row) + " couples to velocity dof " +
                             std::to_string(column) + " (a component declares that it writes position rows)";
        return false;
      }
    }
  if (const auto missing = std::find(pivotEntry_.begin(), pivotEntry_.end(), -1); missing != pivotEntry_.end()) {
    wholeSystemReason_ =
        "position dof " + std::to_string(missing - pivotEntry_.begin()) + " has no kinematic row (no inertia owns it)";
    return false;
  }

  // condensed pattern: kept entries of K, plus the fill of the products K(j, v_i) K(q_i, c)
  std::vector<Eigen::Triplet<double>> entries;
  for (int column = 0; column < n; ++column)
    for (SparseMatrix::InnerIterator it(pattern, column); it; ++it) {
      const int row = static_cast<int>(it.row());
      if (isPosition(row)) continue;
      if (!isVelocity(column)) {
        entries.emplace_back(reducedRow(row), reducedColumn(column), 0.0);
        continue;
      }
      for (const RowEntry& kinematic : kinematicRows_[column - nv])
        entries.emplace_back(reducedRow(row), reducedColumn(kinematic.column), 0.0);
    }
  reduced_.resize(n - nv, n - nv);
  reduced_.setFromTriplets(entries.begin(), entries.end());
  reduced_.makeCompressed();

  // where each kept entry and each product term lands in the condensed values
  for (int column = 0; column < n; ++column)
    for (SparseMatrix::InnerIterator it(pattern, column); it; ++it) {
      const int row = static_cast<int>(it.row());
      if (isPosition(row)) continue;
      const int entry = static_cast<int>(&it.value() - pattern.valuePtr());
      if (!isVelocity(column)) {
        directEntries_.emplace_back(entry, findEntry(reduced_, reducedRow(row), reducedColumn(column)));
        continue;
      }
      const int i = column - nv;
      for (const RowEntry& kinematic : kinematicRows_[i])
        productTerms_.push_back({entry, kinematic.entry, pivotEntry_[i],
                                 findEntry(reduced_, reducedRow(row), reducedColumn(kinematic.column))});
    }
  return true;
}

bool CondensedSolver::factorize(const SparseMatrix& tangent, bool repivot) {
  tangent_ = &tangent;
  if (velocities_ > 0) condenseVelocities(tangent);
  if (!internal_.active()) return lu_->factorize(velocityCondensed(), repivot);
  return internal_.reduce(velocityCondensed()) && lu_->factorize(internal_.reduced(), repivot);
}

void CondensedSolver::condenseVelocities(const SparseMatrix& tangent) {
  const double* k = tangent.valuePtr();
  double* reduced = reduced_.valuePtr();
  std::fill_n(reduced, reduced_.nonZeros(), 0.0);
  for (const auto& [entry, reducedEntry] : directEntries_) reduced[reducedEntry] += k[entry];
  for (const ProductTerm& term : productTerms_)
    reduced[term.reducedEntry] -= k[term.velocityEntry] * k[term.kinematicEntry] / k[term.pivotEntry];
}

void CondensedSolver::solveVelocityCondensed(Eigen::VectorXd& rhs) {
  if (!internal_.active()) {
    lu_->solve(rhs);
    return;
  }
  internal_.reduceRhs(rhs, internalRhs_);
  lu_->solve(internalRhs_);
  internal_.recover(rhs, internalRhs_, internalSolution_);
  rhs.swap(internalSolution_);
}

void CondensedSolver::solve(const Eigen::VectorXd& residual, Eigen::VectorXd& increment) {
  if (velocities_ == 0) {
    increment = -residual;
    solveVelocityCondensed(increment);
    return;
  }
  const SparseMatrix& K = *tangent_;
  const double* k = K.valuePtr();
  const int n = static_cast<int>(K.rows()), nv = velocities_;

  // right-hand side: -r_j + sum_i K(j, v_i) r_qi / d_i over the kept rows j
  reducedRhs_ = -residual.tail(n - nv);
  for (int i = 0; i < nv; ++i) {
    const double factor = residual[i] / k[pivotEntry_[i]];
    for (SparseMatrix::InnerIterator it(K, nv + i); it; ++it)
      if (it.row() >= nv) reducedRhs_[reducedRow(static_cast<int>(it.row()))] += it.value() * factor;
  }
  solveVelocityCondensed(reducedRhs_);

  // kept unknowns, then the velocities from their kinematic rows
  increment.head(nv) = reducedRhs_.head(nv);
  increment.tail(n - 2 * nv) = reducedRhs_.tail(n - 2 * nv);
  for (int i = 0; i < nv; ++i) {
    double sum = residual[i];
    for (const RowEntry& kinematic : kinematicRows_[i]) sum += k[kinematic.entry] * increment[kinematic.column];
    increment[nv + i] = -sum / k[pivotEntry_[i]];
  }
}

std::string CondensedSolver::describe() const {
  const std::string size = std::to_string(condensedSize()) + " of " + std::to_string(pattern_->rows()) +
                           " unknowns factorised by " + lu_->name();
  if (velocities_ > 0)
    return size + " (velocities" + (internal_.active() ? " and internal variables" : "") + " eliminated)";
  return wholeSystemReason_.empty() ? size : size + "; solved whole because " + wholeSystemReason_;
}

}  // namespace mpx
