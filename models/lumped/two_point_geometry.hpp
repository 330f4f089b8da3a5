#pragma once
// The separation d = x_b - x_a between two end points, each a mass point (state dofs) or a
// fixed anchor, and how forces along it enter the momentum rows of the local system.
#include "engine/core/component.hpp"

#include <vector>

namespace mpx {

// A mass point's global dofs (x component; y, z follow) or a fixed point in space.
struct Endpoint {
  int positionDof = -1;
  int velocityDof = -1;
  Vec3 anchor = Vec3::Zero();
  bool isMass() const { return positionDof >= 0; }
};

class TwoPointGeometry {
 public:
  // The local dofs start with those of the mass end points (position then velocity, 3 each).
  TwoPointGeometry(const Endpoint& a, const Endpoint& b);
  // Global indices of those leading local dofs.
  std::vector<int> dofs() const;

  // x_b - x_a in state z.
  Vec3 separation(const double* z) const;
  // Rate of the separation from the position part of zdot.
  Vec3 separationRate(const double* zdot) const;
  // v_b - v_a in state z: the separation rate as the velocities give it. Rate forms use it,
  // because under constraints q' = v - mu dPhi/dq carries the GGL multiplier.
  Vec3 separationVelocity(const double* z) const;
  // Add +force to b's and -force to a's momentum rows.
  void addForce(LocalSystem& local, const Vec3& force) const;
  // Add force-direction x dForce/dz to the momentum rows: b's rows +, a's rows -.
  void addForceTangent(LocalSystem& local, const Vec3& direction, const LocalRow& dForce) const;
  // Add dForce/dd (3x3) for a force that depends on the separation d of the state.
  void addSeparationTangent(LocalSystem& local, const Eigen::Matrix3d& dForceDd) const;
  // Add dForce/dw (3x3) for a force that depends on the separation velocity w of the state.
  void addSeparationVelocityTangent(LocalSystem& local, const Eigen::Matrix3d& dForceDw) const;
  // Row over local dofs of d(w . d)/dz.
  void addSeparationRow(LocalRow& row, const Vec3& w) const;
  // Whether local dof `local` is an end point's position (a row these elements never write).
  bool isPosition(int local) const {
    return (local >= localPositionA_ && local < localPositionA_ + 3 && localPositionA_ >= 0) ||
           (local >= localPositionB_ && local < localPositionB_ + 3 && localPositionB_ >= 0);
  }

 private:
  // Add dForce/dy (3x3) to the momentum rows for columns y of b (+) and a (-).
  void addMomentumTangent(LocalSystem& local, const Eigen::Matrix3d& dForce, int columnB, int columnA) const;

  Endpoint a_, b_;
  int localPositionA_ = -1, localVelocityA_ = -1, localPositionB_ = -1, localVelocityB_ = -1;
};

}  // namespace mpx
