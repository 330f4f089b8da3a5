#include "models/multibody/quadratic_form.hpp"

#include <algorithm>

namespace mpx {

QuadraticForm::QuadraticForm(const ConstraintMatrix& hessian, ConstraintVector gradient, double constant)
    : gradient_(std::move(gradient)), constant_(constant) {
  for (int column = 0; column < hessian.cols(); ++column)
    for (int row = 0; row < hessian.rows(); ++row)
      if (hessian(row, column) != 0.0) entries_.push_back({row, column, hessian(row, column), 0});
  for (const Entry& e : entries_) support_ |= 1u << e.row;
  for (int i = 0; i < gradient_.size(); ++i)
    if (gradient_[i] != 0.0) support_ |= 1u << i;
  for (int i = 0; i < gradient_.size(); ++i)
    if (touches(i)) supportCoordinates_.push_back(i);
  for (Entry& e : entries_)
    e.rowSlot = static_cast<int>(std::find(supportCoordinates_.begin(), supportCoordinates_.end(), e.row) -
                                 supportCoordinates_.begin());
}

double QuadraticForm::valueAndSupportGradient(const ConstraintVector& q, SupportValues& gradient) const {
  const int count = static_cast<int>(supportCoordinates_.size());
  // H q, then + g, in the order of hessianTimes and gradientAt
  std::fill_n(gradient.begin(), count, 0.0);
  for (const Entry& e : entries_) gradient[e.rowSlot] += e.value * q[e.column];
  double twiceQuadratic = 0.0;
  for (int s = 0; s < count; ++s) {
    const int i = supportCoordinates_[s];
    gradient[s] += gradient_[i];
    twiceQuadratic += q[i] * (gradient[s] + gradient_[i]);
  }
  return 0.5 * twiceQuadratic + constant_;
}

ConstraintVector QuadraticForm::fromSupport(const SupportValues& values) const {
  ConstraintVector full = ConstraintVector::Zero(gradient_.size());
  for (std::size_t s = 0; s < supportCoordinates_.size(); ++s) full[supportCoordinates_[s]] = values[s];
  return full;
}

std::uint32_t QuadraticForm::hessianRow(int i) const {
  std::uint32_t row = 0;
  for (const Entry& e : entries_)
    if (e.row == i) row |= 1u << e.column;
  return row;
}

ConstraintVector QuadraticForm::hessianTimes(const ConstraintVector& v) const {
  ConstraintVector product = ConstraintVector::Zero(gradient_.size());
  for (const Entry& e : entries_) product[e.row] += e.value * v[e.column];
  return product;
}

}  // namespace mpx
