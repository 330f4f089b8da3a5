#include "engine/linear/condensed_solver.hpp"

#include <algorithm>

namespace mpx {

namespace {
using SparseMatrix = Eigen::SparseMatrix<double>;
}  // namespace

CondensedSolver::CondensedSolver(const Layout& layout, const SparseMatrix& pattern, bool symmetricPart)
    : factorizedTangent_(pattern), symmetricPart_(symmetricPart) {
  // positions come first in the layout, velocities right after, dof for dof; a collocation
  // step's system (eem4) repeats the layout once per stage, and each stage's kinematic rows
  // pair with its own velocities in the same way
  const int n = layout.total(), stages = static_cast<int>(pattern.rows()) / n;
  const bool paired = layout.has(Block::Position) && layout.size(Block::Position) == layout.size(Block::Velocity) &&
                      layout.offset(Block::Position) == 0;
  if (paired) {
    numberUnknowns(n, layout.size(Block::Position), stages);
    if (!buildCondensation(pattern)) velocities_ = 0;
  }
  reducedRhs_.resize(pattern.rows() - velocities_);
  // every stage's internal variables, numbered as in the velocity-condensed system
  const SparseMatrix& stage = velocities_ > 0 ? reduced_ : pattern;
  const int velocitiesPerStage = velocities_ > 0 ? layout.size(Block::Velocity) : 0;
  std::vector<GroupElimination::Range> internalRanges;
  for (int s = 0; s < stages; ++s)
    internalRanges.push_back({s * (n - velocitiesPerStage) + layout.offset(Block::Internal) - velocitiesPerStage,
                              layout.size(Block::Internal)});
  internal_.build(stage, internalRanges);
  internalRhs_.resize(internal_.active() ? internal_.reduced().rows() : 0);
  internalSolution_.resize(stage.rows());
  lu_ = makeSparseLu(static_cast<int>(factorised().rows()), symmetricPart_);
}

void CondensedSolver::numberUnknowns(int n, int positions, int stages) {
  // unknown u = stage n + i; the kinematic row of position i pairs with velocity u + positions
  stateSize_ = n;
  velocities_ = stages * positions;
  velocityOffset_ = positions;
  kinematicRow_.resize(velocities_);
  kinematicIndex_.assign(stages * n, -1);
  reducedIndex_.assign(stages * n, -1);
  for (int stage = 0; stage < stages; ++stage)
    for (int i = 0; i < n; ++i) {
      const int u = stage * n + i, kept = stage * (n - positions);
      // a position keeps its column, the momentum row of its velocity takes its row's place
      reducedIndex_[u] = kept + (i < positions ? i : i - positions);
      if (i < positions) {
        kinematicRow_[stage * positions + i] = u;
        kinematicIndex_[u] = stage * positions + i;
      }
    }
}

std::string CondensedSolver::dofName(int unknown) const {
  const std::string dof = "dof " + std::to_string(unknown % stateSize_);
  return unknown < stateSize_ ? dof : dof + " of stage " + std::to_string(unknown / stateSize_ + 1);
}

bool CondensedSolver::buildCondensation(const SparseMatrix& pattern) {
  const int n = static_cast<int>(pattern.rows()), nv = velocities_;

  // kinematic rows: their entries in kept columns (by row, and by column for the condensation),
  // and the single velocity entry d_i
  kinematicRows_.assign(nv, {});
  pivotEntry_.assign(nv, -1);
  kinematicColumnStart_.assign(n + 1, 0);
  kinematicColumns_.clear();
  for (int column = 0; column < n; ++column) {
    kinematicColumnStart_[column] = static_cast<int>(kinematicColumns_.size());
    for (SparseMatrix::InnerIterator it(pattern, column); it; ++it) {
      const int row = static_cast<int>(it.row()), k = kinematicIndex_[row];
      if (k < 0) continue;
      const int entry = static_cast<int>(&it.value() - pattern.valuePtr());
      if (!isVelocity(column)) {
        kinematicRows_[k].push_back({column, entry});
        kinematicColumns_.push_back({k, entry});
      } else if (column == velocityOf(k))
        pivotEntry_[k] = entry;
      else {
        wholeSystemReason_ = "the kinematic row of position " + dofName(row) + " couples to velocity " +
                             dofName(column) + " (a component declares that it writes position rows)";
        return false;
      }
    }
  }
  kinematicColumnStart_[n] = static_cast<int>(kinematicColumns_.size());
  if (const auto missing = std::find(pivotEntry_.begin(), pivotEntry_.end(), -1); missing != pivotEntry_.end()) {
    wholeSystemReason_ = "position " + dofName(kinematicRow_[missing - pivotEntry_.begin()]) +
                         " has no kinematic row (no inertia owns it)";
    return false;
  }

  // each velocity column's entries in kept rows (the momentum rows of K(j, v_i))
  couplingStart_.assign(nv + 1, 0);
  velocityCouplings_.clear();
  for (int i = 0; i < nv; ++i) {
    couplingStart_[i] = static_cast<int>(velocityCouplings_.size());
    for (SparseMatrix::InnerIterator it(pattern, velocityOf(i)); it; ++it)
      if (!isPosition(static_cast<int>(it.row())))
        velocityCouplings_.push_back({reducedIndex_[it.row()], static_cast<int>(&it.value() - pattern.valuePtr())});
  }
  couplingStart_[nv] = static_cast<int>(velocityCouplings_.size());

  // condensed pattern, a column at a time: the kept entries of K, plus the fill of the
  // products K(j, v_i) K(q_i, c), each entry once (the products are many times the entries)
  std::vector<Eigen::Triplet<double>> entries;
  std::vector<int> rows;
  std::vector<char> seen(n - nv, 0);
  auto mark = [&](int row) {
    if (seen[row]) return;
    seen[row] = 1;
    rows.push_back(row);
  };
  for (int column = 0; column < n; ++column) {
    if (isVelocity(column)) continue;
    for (SparseMatrix::InnerIterator it(pattern, column); it; ++it)
      if (!isPosition(static_cast<int>(it.row()))) mark(reducedIndex_[it.row()]);
    for (int term = kinematicColumnStart_[column]; term < kinematicColumnStart_[column + 1]; ++term) {
      const int i = kinematicColumns_[term].row;
      for (int e = couplingStart_[i]; e < couplingStart_[i + 1]; ++e) mark(velocityCouplings_[e].row);
    }
    for (const int row : rows) {
      entries.emplace_back(row, reducedIndex_[column], 0.0);
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
  std::copy_n(tangent.valuePtr(), tangent.nonZeros(), factorizedTangent_.valuePtr());
  if (velocities_ > 0) condenseVelocities(factorizedTangent_);
  if (!internal_.active()) return lu_->factorize(velocityCondensed(), repivot);
  return internal_.reduce(velocityCondensed()) && lu_->factorize(internal_.reduced(), repivot);
}

void CondensedSolver::condenseVelocities(const SparseMatrix& tangent) {
  const double* k = tangent.valuePtr();
  const int n = static_cast<int>(tangent.rows());
  double* reduced = reduced_.valuePtr();
  // each condensed column in a dense work column: K(j, c), minus the products in the order of
  // i, then copied into the condensed values (the work column is zero again afterwards); the
  // products are never stored: a rigid link had some 42 000 of them while its constraints
  // claimed more than their forms reach (docs/performance.md)
  for (int column = 0; column < n; ++column) {
    if (isVelocity(column)) continue;
    for (SparseMatrix::InnerIterator it(tangent, column); it; ++it)
      if (!isPosition(static_cast<int>(it.row()))) condensedColumn_[reducedIndex_[it.row()]] += it.value();
    for (int term = kinematicColumnStart_[column]; term < kinematicColumnStart_[column + 1]; ++term) {
      const auto [i, kinematicEntry] = kinematicColumns_[term];
      const double factor = k[kinematicEntry] / k[pivotEntry_[i]];
      for (int e = couplingStart_[i]; e < couplingStart_[i + 1]; ++e)
        condensedColumn_[velocityCouplings_[e].row] -= k[velocityCouplings_[e].entry] * factor;
    }
    const int target = reducedIndex_[column];
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
  const SparseMatrix& K = factorizedTangent_;
  const double* k = K.valuePtr();
  const int n = static_cast<int>(K.rows()), nv = velocities_;

  // right-hand side: -r_j + sum_i K(j, v_i) r_qi / d_i over the kept rows j
  for (int row = 0; row < n; ++row)
    if (!isPosition(row)) reducedRhs_[reducedIndex_[row]] = -residual[row];
  for (int i = 0; i < nv; ++i) {
    const double factor = residual[kinematicRow_[i]] / k[pivotEntry_[i]];
    for (int e = couplingStart_[i]; e < couplingStart_[i + 1]; ++e)
      reducedRhs_[velocityCouplings_[e].row] += k[velocityCouplings_[e].entry] * factor;
  }
  solveVelocityCondensed(reducedRhs_);

  // kept unknowns, then the velocities from their kinematic rows
  for (int column = 0; column < n; ++column)
    if (!isVelocity(column)) increment[column] = reducedRhs_[reducedIndex_[column]];
  for (int i = 0; i < nv; ++i) {
    double sum = residual[kinematicRow_[i]];
    for (const RowEntry& kinematic : kinematicRows_[i]) sum += k[kinematic.entry] * increment[kinematic.column];
    increment[velocityOf(i)] = -sum / k[pivotEntry_[i]];
  }
}

std::string CondensedSolver::describe() const {
  const std::string size = std::to_string(condensedSize()) + " of " + std::to_string(factorizedTangent_.rows()) +
                           " unknowns factorised by " + lu_->name();
  if (velocities_ > 0)
    return size + " (velocities" + (internal_.active() ? " and internal variables" : "") + " eliminated)";
  return wholeSystemReason_.empty() ? size : size + "; solved whole because " + wholeSystemReason_;
}

}  // namespace mpx
