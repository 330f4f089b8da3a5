#pragma once
// The separation d = x_b - x_a between two end points, and how forces along it enter the
// momentum rows of the local system. Each end point is a fixed point in space or a fixed
// linear combination of position dofs (a mass point; a body point phi + X_i d_i), so d is
// linear in the state: discrete gradients through d stay exact, and a force along d acting on
// each end through the transpose of that combination keeps linear and angular momentum.
#include "engine/core/component.hpp"

#include <array>
#include <vector>

namespace mpx {

// x = sum_k weights[k] y_k over `terms` consecutive 3-vectors y_k of position dofs from
// positionDof (a mass: its position; a body point: the centre of mass and the three directors
// with the point's body coordinates), its velocity the same combination from velocityDof;
// with no terms, the fixed point `anchor`.
struct Endpoint {
  static constexpr int kMaxTerms = 4;
  int positionDof = -1;
  int velocityDof = -1;
  int terms = 0;
  std::array<double, kMaxTerms> weights{};
  Vec3 anchor = Vec3::Zero();

  static Endpoint fixed(const Vec3& position);
  static Endpoint point(int positionDof, int velocityDof);
  // phi + X_i d_i of a body whose phi, d1, d2, d3 start at positionDof.
  static Endpoint bodyPoint(int positionDof, int velocityDof, const Vec3& bodyCoordinates);
  bool moves() const { return terms > 0; }
  // The point in state z (the anchor for a fixed point).
  Vec3 in(const double* z) const;
};

class TwoPointGeometry {
 public:
  // The local dofs are those of the moving end points, each end's position terms then its
  // velocity terms (3 each).
  TwoPointGeometry(const Endpoint& a, const Endpoint& b);
  // Global indices of those local dofs.
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
  // The pattern of a two-point element: the momentum rows (never the ends' kinematic rows),
  // against the positions and, for an element whose force reads them, the velocities.
  bool couples(int row, int column, bool readsVelocities) const {
    return !isPosition(row) && (readsVelocities || !isVelocity(column));
  }

 private:
  // Whether local dof `local` is an end point's position, or its velocity.
  bool isPosition(int local) const;
  bool isVelocity(int local) const;
  // An end point with the sign of its force (b +, a -) and where its dofs sit locally.
  struct End {
    Endpoint point;
    double sign = 1.0;
    int localPosition = -1, localVelocity = -1;
  };
  // Whether `local` lies in a moving end's block that starts at its `first` (positions or
  // velocities).
  bool inEndBlock(int local, int End::*first) const;
  // Add dForce/dy (3x3) to the momentum rows, y the position (or velocity) terms of the ends.
  void addMomentumTangent(LocalSystem& local, const Eigen::Matrix3d& dForce, bool velocityColumns) const;

  std::array<End, 2> ends_;  // b, a
};

}  // namespace mpx
