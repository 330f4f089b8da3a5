#include "engine/linear/condensed_solver.hpp"

#include <algorithm>

namespace mpx {

namespace {
using SparseMatrix = Eigen::SparseMatrix<double>;
}  // namespace

CondensedSolver::CondensedSolver(const Layout& layout, const SparseMatrix& pattern) : pattern_(&pattern) {
  // positions come first in the layout, velocities right after, dof for dof; the system of
  // several stages (eem4) is solved whole
  const bool oneStage = pattern.rows() == layout.total();
  if (!oneStage) wholeSystemReason_ = "it is the stage system of a collocation step";
  const bool paired = oneStage && layout.has(Block::Position) &&
                      layout.size(Block::Position) == layout.size(Block::Velocity) &&
                      layout.offset(Block::Position) == 0;
  velocities_ = paired ? layout.size(Block::Velocity) : 0;
  if (velocities_ > 0 && !buildCondensation(pattern)) velocities_ = 0;
  reducedRhs_.resize(pattern.rows() - velocities_);
  // internal variables, numbered as in the velocity-condensed system
  const SparseMatrix& stage = velocities_ > 0 ? reduced_ : pattern;
  internal_.build(stage, layout.offset(Block::Internal) - velocities_, oneStage ? layout.size(Block::Internal) : 0);
  internalRhs_.resize(internal_.active() ? internal_.reduced().rows() : 0);
  internalSolution_.resize(stage.rows());
  lu_ = makeSparseLu(static_cast<int>(factorised().rows()));
}

bool CondensedSolver::buildCondensation(const SparseMatrix& pattern) {
  const int n = static_cast<int>(pattern.rows()), nv = velocities_;
  auto isPosition = [&](int dof) { return dof < nv; };
  auto isVelocity = [&](int dof) { return dof >= nv && dof < 2 * nv; };

  // kinematic rows: their entries in kept columns (by row, and by column for the condensation),
  // and the single velocity entry d_i
  kinematicRows_.assign(nv, {});
  pivotEntry_.assign(nv, -1);
  kinematicColumnStart_.assign(n + 1, 0);
  kinematicColumns_.clear();
  for (int column = 0; column < n; ++column) {
    kinematicColumnStart_[column] = static_cast<int>(kinematicColumns_.size());
    for (SparseMatrix::InnerIterator it(pattern, column); it; ++it) {
      const int row = static_cast<int>(it.row());
      if (!isPosition(row)) continue;
      const int entry = static_cast<int>(&it.value() - pattern.valuePtr());
      if (!isVelocity(column)) {
        kinematicRows_[row].push_back({column, entry});
        kinematicColumns_.push_back({row, entry});
      } else if (column - nv == row)
        pivotEntry_[row] = entry;
      else {
        wholeSystemReason_ = "the kinematic row of position dof " + std::to_string(row) + " couples to velocity dof " +
                             std::to_string(column) + " (a component declares that it writes position rows)";
        return false;
      }
    }
  }
  kinematicColumnStart_[n] = static_cast<int>(kinematicColumns_.size());
  if (const auto missing = std::find(pivotEntry_.begin(), pivotEntry_.end(), -1); missing != pivotEntry_.end()) {
    wholeSystemReason_ =
        "position dof " + std::to_string(missing - pivotEntry_.begin()) + " has no kinematic row (no inertia owns it)";
    return false;
  }

  // condensed pattern, a column at a time: the kept entries of K, plus the fill of the
  // products K(j, v_i) K(q_i, c), each entry once (the products are many times the entries)
  std::vector<Eigen::Triplet<double>> entries;
  std::vector<int> rows;
  std::vector<char> seen(n - nv, 0);
  auto mark = [&](int row) {
    if (row < nv || seen[reducedRow(row)]) return;
    seen[reducedRow(row)] = 1;
    rows.push_back(reducedRow(row));
  };
  for (int column = 0; column < n; ++column) {
    if (isVelocity(column)) continue;
    for (SparseMatrix::InnerIterator it(pattern, column); it; ++it) mark(static_cast<int>(it.row()));
    for (int k = kinematicColumnStart_[column]; k < kinematicColumnStart_[column + 1]; ++k)
      for (SparseMatrix::InnerIterator it(pattern, nv + kinematicColumns_[k].position); it; ++it)
        mark(static_cast<int>(it.row()));
    for (const int row : rows) {
      entries.emplace_back(row, reducedColumn(column), 0.0);
      seen[row] = 0;
    }
    rows.clear();
  }
  reduced_.resize(n - nv, n - nv);
  reduced_.setFromTriplets(entries.begin(), entries.end());
  reduced_.makeCompressed();
  condensedColumn_.setZero(n - nv);
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
  const int n = static_cast<int>(tangent.rows()), nv = velocities_;
  double* reduced = reduced_.valuePtr();
  // each condensed column in a dense work column: K(j, c), minus the products in the order of
  // i, then copied into the condensed values (the work column is zero again afterwards)
  for (int column = 0; column < n; ++column) {
    if (column >= nv && column < 2 * nv) continue;
    for (SparseMatrix::InnerIterator it(tangent, column); it; ++it)
      if (it.row() >= nv) condensedColumn_[reducedRow(static_cast<int>(it.row()))] += it.value();
    for (int term = kinematicColumnStart_[column]; term < kinematicColumnStart_[column + 1]; ++term) {
      const auto [i, kinematicEntry] = kinematicColumns_[term];
      for (SparseMatrix::InnerIterator it(tangent, nv + i); it; ++it)
        if (it.row() >= nv)
          condensedColumn_[reducedRow(static_cast<int>(it.row()))] -=
              it.value() * k[kinematicEntry] / k[pivotEntry_[i]];
    }
    const int target = reducedColumn(column);
    for (int e = reduced_.outerIndexPtr()[target]; e < reduced_.outerIndexPtr()[target + 1]; ++e) {
      double& value = condensedColumn_[reduced_.innerIndexPtr()[e]];
      reduced[e] = value;
      value = 0.0;
    }
  }
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
