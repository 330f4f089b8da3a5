#pragma once
// A quadratic function of the coordinates of at most two rigid bodies (position and three
// directors each: 24), phi(q) = 1/2 q.H q + g.q + c. Joint conditions, director rigidity and
// joint invariants are all of this kind in the director formulation (docs/theory.md sections
// 6-7). A condition touches a few of the 24 coordinates, so H is kept as its nonzeros and every
// product goes through them.
#include <Eigen/Dense>

#include <array>
#include <cstdint>
#include <vector>

namespace mpx {

// Largest number of position dofs one constraint set couples (two rigid bodies).
inline constexpr int kMaxConstrainedDofs = 24;  // at most 32: a form's support is a bit mask
using ConstraintVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxConstrainedDofs, 1>;
using ConstraintMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxConstrainedDofs, kMaxConstrainedDofs>;
using ConstraintRow = Eigen::Matrix<double, 1, Eigen::Dynamic, Eigen::RowMajor, 1, kMaxConstrainedDofs>;
// Values at a form's support coordinates, in the order of QuadraticForm::supportCoordinates().
using SupportValues = std::array<double, kMaxConstrainedDofs>;

class QuadraticForm {
 public:
  // H symmetric, of the size of g.
  QuadraticForm(const ConstraintMatrix& hessian, ConstraintVector gradient, double constant);

  // H v
  ConstraintVector hessianTimes(const ConstraintVector& v) const;
  // grad phi(q) = H q + g
  ConstraintVector gradientAt(const ConstraintVector& q) const { return hessianTimes(q) + gradient_; }
  // phi(q), through the support as the residuals take it
  double valueAt(const ConstraintVector& q) const {
    SupportValues gradient;
    return valueAndSupportGradient(q, gradient);
  }
  // phi(q), and grad phi(q) at the support coordinates only: the residual of a constraint works
  // on the few coordinates a form touches instead of all n (up to 24)
  double valueAndSupportGradient(const ConstraintVector& q, SupportValues& gradient) const;
  // The coordinates phi depends on, in increasing order.
  const std::vector<int>& supportCoordinates() const { return supportCoordinates_; }
  // Support values as a vector of all n coordinates (zero off the support).
  ConstraintVector fromSupport(const SupportValues& values) const;
  // target[i] += factor values_i over the support coordinates i, for target (an expression of) a
  // vector of all n coordinates
  template <class Target>
  void addOnSupport(double factor, const SupportValues& values, Target&& target) const {
    for (std::size_t s = 0; s < supportCoordinates_.size(); ++s) target[supportCoordinates_[s]] += factor * values[s];
  }
  // sum over the support coordinates i of values_i v_i
  double dotOnSupport(const SupportValues& values, const ConstraintVector& v) const {
    double sum = 0.0;
    for (std::size_t s = 0; s < supportCoordinates_.size(); ++s) sum += values[s] * v[supportCoordinates_[s]];
    return sum;
  }
  // Whether phi depends on coordinate i (its gradient's entry i can be non-zero).
  bool touches(int i) const { return support_ >> i & 1u; }
  // The coordinates phi depends on, and those H couples to coordinate i, as bit masks.
  std::uint32_t support() const { return support_; }
  std::uint32_t hessianRow(int i) const;
  // K += factor H, for K (an expression of) the n x n block of the coordinates
  template <class Block>
  void addHessian(double factor, Block&& K) const {
    for (const Entry& e : entries_) K(e.row, e.column) += factor * e.value;
  }

 private:
  struct Entry {
    int row, column;
    double value;
    int rowSlot;  // the position of row in supportCoordinates_
  };
  std::vector<Entry> entries_;  // H's nonzeros, by column
  ConstraintVector gradient_;
  double constant_;
  std::uint32_t support_ = 0;  // bit i: H's row i or g_i is non-zero
  std::vector<int> supportCoordinates_;
};

}  // namespace mpx
