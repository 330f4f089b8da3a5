#include "engine/linear/corotation.hpp"

#include <Eigen/SVD>

#include <algorithm>

namespace mpx {

Corotation::Corotation(const Model& model, int stages) : stateSize_(model.layout().total()), stages_(stages) {
  for (const auto& component : model.components()) component->spatialVectors(vectors_);
  // the configuration's vectors first: they alone fix the rotation
  const auto forces = std::stable_partition(vectors_.begin(), vectors_.end(), [](const Component::SpatialVector& v) {
    return v.kind != Component::SpatialVector::Kind::Force;
  });
  configuration_ = static_cast<int>(forces - vectors_.begin());
  for (int k = 0; k < configuration_; ++k) points_ += isPoint(k) ? 1 : 0;
  anchored_.resize(configuration_);
}

namespace {
Eigen::Vector3d at(const Eigen::VectorXd& z, int dof) { return z.segment<3>(dof); }
}  // namespace

Eigen::Vector3d Corotation::pointCentroid(const Eigen::VectorXd& z) const {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int k = 0; k < configuration_; ++k)
    if (isPoint(k)) centroid += at(z, vectors_[k].first);
  return points_ > 0 ? Eigen::Vector3d(centroid / points_) : centroid;
}

void Corotation::anchor(const Eigen::VectorXd& z) {
  for (int k = 0; k < configuration_; ++k) anchored_[k] = at(z, vectors_[k].first);
  anchoredCentroid_ = pointCentroid(z);
  rotation_.setIdentity();
  turned_ = false;
}

void Corotation::follow(const Eigen::VectorXd& z) {
  if (configuration_ == 0) return;
  // Kabsch: R = V U^T from the SVD U S V^T of the correlation sum a b^T of the anchored
  // vectors a and the current ones b (points about their centroids, directions as they are),
  // with the last singular direction flipped if that gives a reflection
  const Eigen::Vector3d centroid = pointCentroid(z);
  Eigen::Matrix3d correlation = Eigen::Matrix3d::Zero();
  for (int k = 0; k < configuration_; ++k) {
    const Eigen::Vector3d a = anchored_[k], b = at(z, vectors_[k].first);
    correlation +=
        isPoint(k) ? Eigen::Matrix3d((a - anchoredCentroid_) * (b - centroid).transpose()) : a * b.transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(correlation, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d v = svd.matrixV();
  if ((v * svd.matrixU().transpose()).determinant() < 0.0) v.col(2) *= -1.0;
  rotation_ = v * svd.matrixU().transpose();
  turned_ = !rotation_.isIdentity(0.0);
}

void Corotation::solve(CondensedSolver& solver, const Eigen::VectorXd& residual, Eigen::VectorXd& work,
                       Eigen::VectorXd& increment) const {
  if (!turned_) {
    solver.solve(residual, increment);
    return;
  }
  work = residual;
  toAnchor(work);
  solver.solve(work, increment);
  fromAnchor(increment);
}

void Corotation::turn(Eigen::VectorXd& v, const Eigen::Matrix3d& rotation) const {
  for (int stage = 0; stage < stages_; ++stage)
    for (const auto& vector : vectors_)
      for (const int first : {vector.first, vector.paired}) {
        auto entry = v.segment<3>(stage * stateSize_ + first);
        entry = rotation * Eigen::Vector3d(entry);
      }
}

}  // namespace mpx
