#include "assembler.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mpx {

Assembler::Assembler(const Model& model) {
  const int n = model.layout().total();
  residual_ = Eigen::VectorXd::Zero(n);
  rowScale_ = Eigen::VectorXd::Zero(n);

  // pattern: every pair of a component's dofs, plus the diagonal
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < n; ++i) entries.emplace_back(i, i, 0.0);
  for (const auto& component : model.components()) {
    const auto& dofs = component->dofs();
    if (dofs.size() > static_cast<std::size_t>(kMaxLocalDofs))
      throw std::logic_error("component '" + component->name() + "' touches more than kMaxLocalDofs dofs");
    for (int row : dofs)
      for (int col : dofs) entries.emplace_back(row, col, 0.0);
  }
  tangent_.resize(n, n);
  tangent_.setFromTriplets(entries.begin(), entries.end());
  tangent_.makeCompressed();

  // scatter map: position of (row, col) in the compressed column `col`
  const int* outer = tangent_.outerIndexPtr();
  const int* inner = tangent_.innerIndexPtr();
  for (const auto& component : model.components()) {
    const auto& dofs = component->dofs();
    std::vector<int> index(dofs.size() * dofs.size());
    for (std::size_t j = 0; j < dofs.size(); ++j)
      for (std::size_t i = 0; i < dofs.size(); ++i) {
        const int* begin = inner + outer[dofs[j]];
        const int* end = inner + outer[dofs[j] + 1];
        index[i + j * dofs.size()] = static_cast<int>(std::lower_bound(begin, end, dofs[i]) - inner);
      }
    valueIndex_.push_back(std::move(index));
  }
  localResidual_.assign(kMaxLocalDofs, 0.0);
  localTangent_.assign(kMaxLocalDofs * kMaxLocalDofs, 0.0);
}

void Assembler::clear() {
  residual_.setZero();
  std::fill_n(tangent_.valuePtr(), tangent_.nonZeros(), 0.0);
  flows_ = Flows{};
}

void Assembler::scatter(std::size_t component, const std::vector<int>& dofs, const LocalSystem& local,
                        double weight) {
  const std::vector<int>& index = valueIndex_[component];
  double* values = tangent_.valuePtr();
  for (int i = 0; i < local.n; ++i) residual_[dofs[i]] += weight * local.r[i];
  for (int e = 0; e < local.n * local.n; ++e) values[index[e]] += weight * local.k[e];
}


void Assembler::updateRowScale(const Eigen::VectorXd& stateScale) {
  rowScale_.setZero();
  for (int col = 0; col < tangent_.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(tangent_, col); it; ++it)
      rowScale_[it.row()] += std::abs(it.value()) * stateScale[col];
}

double Assembler::relativeResidualNorm() const {
  double norm = 0.0;
  for (Eigen::Index i = 0; i < residual_.size(); ++i) {
    if (!std::isfinite(residual_[i])) return INFINITY;
    if (residual_[i] != 0.0) norm = std::max(norm, std::abs(residual_[i]) / rowScale_[i]);
  }
  return norm;
}

}  // namespace mpx
