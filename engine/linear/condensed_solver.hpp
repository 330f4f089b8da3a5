#pragma once
// The Newton system of a step, K dz = -r, solved with the velocity increments eliminated.
// Every position dof q_i has a kinematic row (q_i' - q_i)/dt - (v_i + v_i')/2 (or its rate
// form) whose only velocity entry is d_i = dR_qi/dv_i. That row gives
//   dv_i = -(r_qi + sum_c K(q_i, c) dz_c) / d_i          (c: all dofs but velocities)
// and substituting it leaves a system in positions, thermal, internal and multiplier
// unknowns only, with the momentum rows in place of the kinematic ones: half the size for
// mechanics and of the sparsity of a stiffness matrix (2 M/dt^2 + K/2 on its diagonal).
// A collocation step's system (eem4: the layout once per stage) is condensed stage by stage
// in the same way. Scenes whose pattern does not have this structure are solved whole.
// Internal variables that split into small independent groups (per quadrature point, per
// Maxwell element, both stages of one together) are then eliminated as well
// (engine/linear/group_elimination), so that what is factorised is the system of positions,
// thermal unknowns and multipliers.
#include "engine/core/layout.hpp"
#include "engine/linear/group_elimination.hpp"
#include "engine/linear/sparse_lu.hpp"

#include <Eigen/Sparse>

#include <memory>
#include <string>
#include <vector>

namespace mpx {

class CondensedSolver {
 public:
  // `pattern`: the fixed pattern of every tangent this solver will see. `symmetricPart`: a large
  // condensed system is factorised by its symmetric part (an approximation, for simplified
  // Newton only; engine/linear/cholmod_solver.hpp).
  CondensedSolver(const Layout& layout, const Eigen::SparseMatrix<double>& pattern, bool symmetricPart = false);

  // Factorise the condensed form of `tangent` (of the pattern given at construction). Its values
  // are kept, since solve reads its kinematic rows and velocity couplings: the tangent may be
  // re-assembled, or left unevaluated, while the factorisation is reused (simplified Newton).
  // Returns false if singular.
  bool factorize(const Eigen::SparseMatrix<double>& tangent, bool repivot);
  // Forget the factorisation, its pivots and analysis: the next factorize starts as the first.
  void startAfresh() { lu_ = makeSparseLu(static_cast<int>(factorised().rows()), symmetricPart_); }
  // increment = -K^{-1} residual for the last factorised K. Allocates nothing.
  void solve(const Eigen::VectorXd& residual, Eigen::VectorXd& increment);
  // Whether the last factorisation is of the (condensed) tangent itself, not an approximation.
  bool factorisesTheTangent() const { return !lu_->approximates(); }
  // Unknowns of the system actually factorised.
  int condensedSize() const { return static_cast<int>(factorised().rows()); }
  // Why the velocities could not be eliminated ("" when they are, or when there are none).
  const std::string& wholeSystemReason() const { return wholeSystemReason_; }
  // One line for run summaries: what is factorised, and why it is not condensed if it is not.
  std::string describe() const;

 private:
  // An entry of kinematic row i off its velocity: column c (a kept dof) and its place in K.
  struct RowEntry {
    int column, entry;
  };
  // An entry seen from its column: its row (a kinematic row i, or a kept row's condensed index)
  // and its place in K.
  struct ColumnEntry {
    int row, entry;
  };
  // The maps below for `stages` copies of a layout of n dofs with `positions` positions.
  void numberUnknowns(int n, int positions, int stages);
  bool buildCondensation(const Eigen::SparseMatrix<double>& pattern);
  // "dof i", or "dof i of stage l" in a collocation step's system, for messages
  std::string dofName(int unknown) const;
  void condenseVelocities(const Eigen::SparseMatrix<double>& tangent);
  // Solve the velocity-condensed system in place, through the internal elimination if any.
  void solveVelocityCondensed(Eigen::VectorXd& rhs);
  bool isPosition(int unknown) const { return kinematicIndex_[unknown] >= 0; }
  bool isVelocity(int unknown) const {
    // velocity i of a stage sits `positions` after position i; no other unknown does (n >= 2 positions)
    return unknown >= velocityOffset_ && isPosition(unknown - velocityOffset_);
  }
  // the velocity unknown of kinematic row i
  int velocityOf(int i) const { return kinematicRow_[i] + velocityOffset_; }
  // The matrix after velocity condensation (the tangent itself without it).
  const Eigen::SparseMatrix<double>& velocityCondensed() const {
    return velocities_ > 0 ? reduced_ : factorizedTangent_;
  }
  const Eigen::SparseMatrix<double>& factorised() const {
    return internal_.active() ? internal_.reduced() : velocityCondensed();
  }

  int velocities_ = 0;      // velocity unknowns eliminated, all stages (0: solved whole)
  int velocityOffset_ = 0;  // from a position unknown to its velocity
  int stateSize_ = 0;       // of one stage
  // per kinematic row i (all stages): its position unknown; per unknown: its kinematic row
  // (-1 if not a position), and its index in the condensed system as a kept row or column
  // (a velocity's momentum row takes its position's place)
  std::vector<int> kinematicRow_, kinematicIndex_, reducedIndex_;
  std::string wholeSystemReason_;
  Eigen::SparseMatrix<double> factorizedTangent_;  // the tangent last factorised (its pattern before)
  Eigen::SparseMatrix<double> reduced_;
  std::vector<int> pivotEntry_;                       // per kinematic row i (all stages): place of d_i in K
  std::vector<std::vector<RowEntry>> kinematicRows_;  // per kinematic row i (all stages)
  // the kinematic entries of column c of K are kinematicColumns_[kinematicColumnStart_[c] ...
  // kinematicColumnStart_[c + 1]), in the order of i
  std::vector<ColumnEntry> kinematicColumns_;
  std::vector<int> kinematicColumnStart_;
  Eigen::VectorXd condensedColumn_;  // zero between uses
  // per kinematic row i, its velocity column's entries in kept rows:
  // velocityCouplings_[couplingStart_[i] ... couplingStart_[i + 1])
  std::vector<ColumnEntry> velocityCouplings_;
  std::vector<int> couplingStart_;
  Eigen::VectorXd reducedRhs_;
  GroupElimination internal_;
  Eigen::VectorXd internalRhs_, internalSolution_;  // of the system after velocity condensation
  bool symmetricPart_;
  std::unique_ptr<SparseLu> lu_;
};

}  // namespace mpx
