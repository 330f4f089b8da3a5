#include "models/multibody/quadratic_form.hpp"

namespace mpx {

QuadraticForm::QuadraticForm(const ConstraintMatrix& hessian, ConstraintVector gradient, double constant)
    : gradient_(std::move(gradient)), constant_(constant) {
  for (int column = 0; column < hessian.cols(); ++column)
    for (int row = 0; row < hessian.rows(); ++row)
      if (hessian(row, column) != 0.0) entries_.push_back({row, column, hessian(row, column)});
  for (const Entry& e : entries_) support_ |= 1u << e.row;
  for (int i = 0; i < gradient_.size(); ++i)
    if (gradient_[i] != 0.0) support_ |= 1u << i;
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
