#include "models/multibody/redundant_constraints.hpp"

#include <Eigen/OrderingMethods>
#include <Eigen/SparseQR>

#include <fmt/format.h>

#include <algorithm>
#include <unordered_map>
#include <unordered_set>
#include <utility>

namespace mpx {

namespace {

// A gradient (scaled to length 1) is redundant when what the earlier ones leave of it is
// shorter than this: an exact dependence leaves round-off (~1e-15), a near-singular but
// genuine geometry leaves far more.
constexpr double kDependenceTolerance = 1e-9;

// Constraint sets a message names before it only counts the rest.
constexpr std::size_t kNamedInMessage = 8;

struct FormColumn {
  QuadraticConstraint* constraint;
  std::size_t form;
};

// Union-find over what constraints join, to tell the sets that lie in a closed loop.
class Mechanisms {
 public:
  explicit Mechanisms(const std::vector<ConstraintEdge>& edges) {
    for (const ConstraintEdge& edge : edges) {
      if (edge.ends.first == edge.ends.second) continue;  // a body's rigidity joins nothing
      const int a = root(edge.ends.first), b = root(edge.ends.second);
      if (a == b) {
        closed_.insert(a);  // a second path between two joined things: a loop
        continue;
      }
      parent_[a] = b;
      if (closed_.count(a)) closed_.insert(b);
    }
  }
  bool inLoop(const ConstraintEdge& edge) { return closed_.count(root(edge.ends.first)) > 0; }

 private:
  // with path compression: a long chain stays cheap
  int root(int node) {
    int top = parent_.emplace(node, node).first->second;
    while (parent_[top] != top) top = parent_[top];
    while (node != top) node = std::exchange(parent_[node], top);
    return top;
  }
  std::unordered_map<int, int> parent_;
  std::unordered_set<int> closed_;
};

}  // namespace

std::vector<RedundantConditions> holdRedundantMultipliers(const std::vector<ConstraintEdge>& constraints,
                                                          const Eigen::VectorXd& z) {
  // one column per augmented-Lagrangian condition in a loop: its unit gradient, in
  // declaration order
  Mechanisms mechanisms(constraints);
  std::vector<Eigen::Triplet<double>> entries;
  std::vector<FormColumn> columns;
  for (const ConstraintEdge& edge : constraints) {
    QuadraticConstraint* constraint = edge.constraint;
    const ConstraintSpec& spec = constraint->spec();
    if (spec.enforcement != Enforcement::AugmentedLagrangian || !mechanisms.inLoop(edge)) continue;
    ConstraintVector q(static_cast<Eigen::Index>(spec.positionDofs.size()));
    for (Eigen::Index i = 0; i < q.size(); ++i) q[i] = z[spec.positionDofs[i]];
    for (std::size_t k = 0; k < spec.forms.size(); ++k) {
      const ConstraintVector gradient = spec.forms[k].gradientAt(q);
      const double length = gradient.norm();
      const auto column = static_cast<int>(columns.size());
      for (Eigen::Index i = 0; i < gradient.size(); ++i)
        if (gradient[i] != 0.0) entries.emplace_back(spec.positionDofs[i], column, gradient[i] / length);
      columns.push_back({constraint, k});
    }
  }
  if (columns.empty()) return {};
  Eigen::SparseMatrix<double> gradients(z.size(), static_cast<Eigen::Index>(columns.size()));
  gradients.setFromTriplets(entries.begin(), entries.end());
  gradients.makeCompressed();

  // natural ordering keeps declaration order: a dependent column moves behind the rank
  Eigen::SparseQR<Eigen::SparseMatrix<double>, Eigen::NaturalOrdering<int>> qr;
  qr.setPivotThreshold(kDependenceTolerance);
  qr.compute(gradients);
  std::vector<int> dependent(qr.colsPermutation().indices().data() + qr.rank(),
                             qr.colsPermutation().indices().data() + columns.size());
  std::sort(dependent.begin(), dependent.end());

  std::vector<RedundantConditions> redundant;
  const QuadraticConstraint* previous = nullptr;
  for (int column : dependent) {
    const FormColumn& c = columns[column];
    c.constraint->holdMultipliersAtZero(c.form);
    if (c.constraint != previous) redundant.push_back({c.constraint->name(), {}, c.constraint->spec().forms.size()});
    previous = c.constraint;
    redundant.back().forms.push_back(c.form);
  }
  return redundant;
}

std::string describeRedundancy(const std::vector<RedundantConditions>& redundant) {
  std::string text;
  for (std::size_t i = 0; i < std::min(redundant.size(), kNamedInMessage); ++i)
    text += fmt::format("{}'{}' ({} of {})", i ? ", " : "", redundant[i].constraint, redundant[i].forms.size(),
                        redundant[i].formCount);
  if (redundant.size() > kNamedInMessage) text += fmt::format(" and {} more", redundant.size() - kNamedInMessage);
  return text;
}

}  // namespace mpx
