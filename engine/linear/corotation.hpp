#pragma once
// A factorisation kept across steps (simplified Newton, IDA's Newton matrix) turned with the
// scene. Where the model is invariant under rotations, its tangent follows the configuration as
// K(Q z) = Q K(z) Q^T, with Q turning every spatial 3-vector of the state (points and directors,
// their velocities, the multipliers of constraints that make two points coincide) by one
// rotation R. A factorisation made at configuration z_f then serves a configuration z close to
// Q z_f as
//   dz = -Q K(z_f)^{-1} Q^T r,
// with R the rotation that best carries z_f's points and directions onto z's (least squares,
// points about their centroid). A scene that turns as a whole (the flyball governor spins at
// 2 pi rad/s) keeps one factorisation for many steps this way, where the factorisation taken as
// it was stops contracting within a few degrees. Scalars, internal variables and the
// multipliers of scalar constraints are left as they are; where the model is not invariant, or
// R fits badly, the correction is simply worse and Newton, judged on the true residual,
// refreshes the factorisation as before.
#include "engine/core/component.hpp"
#include "engine/core/model.hpp"
#include "engine/linear/condensed_solver.hpp"

#include <Eigen/Dense>

#include <vector>

namespace mpx {

class Corotation {
 public:
  // The model's spatial vectors, in each of `stages` copies of its layout (eem4's stage values).
  Corotation(const Model& model, int stages);

  // The configuration the factorisation is made at: no rotation from here.
  void anchor(const Eigen::VectorXd& z);
  // The rotation that best carries the anchor's points and directions onto z's.
  void follow(const Eigen::VectorXd& z);
  // Whether follow found a rotation other than the identity.
  bool turned() const { return turned_; }
  // Turn the spatial vectors of a residual into the anchor's frame (R^T), and of an increment
  // from it (R), in every stage.
  void toAnchor(Eigen::VectorXd& v) const { turn(v, rotation_.transpose()); }
  void fromAnchor(Eigen::VectorXd& v) const { turn(v, rotation_); }
  // increment = the correction for `residual` from `solver`'s factorisation, made at the anchor,
  // turned with the scene: R K_f^{-1} R^T applied (`work` holds the residual in the anchor's frame).
  void solve(CondensedSolver& solver, const Eigen::VectorXd& residual, Eigen::VectorXd& work,
             Eigen::VectorXd& increment) const;

 private:
  void turn(Eigen::VectorXd& v, const Eigen::Matrix3d& rotation) const;
  // the centroid of z's points (zero without points)
  Eigen::Vector3d pointCentroid(const Eigen::VectorXd& z) const;
  bool isPoint(int k) const { return vectors_[k].kind == Component::SpatialVector::Kind::Point; }

  // the configuration's vectors (points and directions) first, configuration_ of them
  std::vector<Component::SpatialVector> vectors_;
  int configuration_ = 0;
  int stateSize_, stages_;
  std::vector<Eigen::Vector3d> anchored_;  // per configuration vector, its value at the anchor
  Eigen::Vector3d anchoredCentroid_ = Eigen::Vector3d::Zero();
  int points_ = 0;
  Eigen::Matrix3d rotation_ = Eigen::Matrix3d::Identity();
  bool turned_ = false;
};

}  // namespace mpx
