#include "engine/linear/corotation.hpp"

#include <Eigen/SVD>

namespace mpx {

Corotation::Corotation(const Model& model, int stages) : stateSize_(model.layout().total()), stages_(stages) {
  for (const auto& component : model.components()) component->spatialVectors(vectors_);
  anchored_.resize(vectors_.size());
  for (const auto& vector : vectors_) points_ += vector.point ? 1 : 0;
}

namespace {
Eigen::Vector3d at(const Eigen::VectorXd& z, int dof) { return z.segment<3>(dof); }
}  // namespace

void Corotation::anchor(const Eigen::VectorXd& z) {
  anchoredCentroid_.setZero();
  for (std::size_t k = 0; k < vectors_.size(); ++k) {
    anchored_[k] = at(z, vectors_[k].position);
    if (vectors_[k].point) anchoredCentroid_ += anchored_[k];
  }
  if (points_ > 0) anchoredCentroid_ /= points_;
  rotation_.setIdentity();
  turned_ = false;
}

void Corotation::follow(const Eigen::VectorXd& z) {
  if (vectors_.empty()) return;
  // Kabsch: R = V U^T from the SVD U S V^T of the correlation sum a b^T of the anchored
  // vectors a and the current ones b (points about their centroids, directors as they are),
  // with the last singular direction flipped if that gives a reflection
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& vector : vectors_)
    if (vector.point) centroid += at(z, vector.position);
  if (points_ > 0) centroid /= points_;
  Eigen::Matrix3d correlation = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < vectors_.size(); ++k) {
    const bool point = vectors_[k].point;
    const Eigen::Vector3d a = point ? Eigen::Vector3d(anchored_[k] - anchoredCentroid_) : anchored_[k];
    const Eigen::Vector3d b =
        point ? Eigen::Vector3d(at(z, vectors_[k].position) - centroid) : at(z, vectors_[k].position);
    correlation += a * b.transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(correlation, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d v = svd.matrixV();
  if ((v * svd.matrixU().transpose()).determinant() < 0.0) v.col(2) *= -1.0;
  rotation_ = v * svd.matrixU().transpose();
  turned_ = !rotation_.isIdentity(0.0);
}

void Corotation::turn(Eigen::VectorXd& v, const Eigen::Matrix3d& rotation) const {
  for (int stage = 0; stage < stages_; ++stage)
    for (const auto& vector : vectors_)
      for (const int first : {vector.position, vector.velocity}) {
        auto entry = v.segment<3>(stage * stateSize_ + first);
        entry = rotation * Eigen::Vector3d(entry);
      }
}

}  // namespace mpx
