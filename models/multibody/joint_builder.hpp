#pragma once
// Quadratic constraint forms of joints and of director rigidity, built from affine maps
// q -> R^3 of material points and material directions of the attached frames (docs/theory.md
// section 7): a body point is phi + X_i d_i, a body direction a_i d_i, both linear in q; a mass
// point is x; the ground is constant. Points and directions are given in world coordinates at
// the initial time and converted to body coordinates here.
#include "models/multibody/quadratic_constraint.hpp"

#include <optional>
#include <string>

namespace mpx {

using Mat3 = Eigen::Matrix3d;

// What a joint attaches to.
struct Attachment {
  enum class Kind { Ground, Point, Body };
  Kind kind = Kind::Ground;
  int firstPositionDof = -1;          // x (Point) or phi, d1, d2, d3 (Body)
  Vec3 position = Vec3::Zero();       // initial x or phi
  Mat3 directors = Mat3::Identity();  // initial d1, d2, d3 as columns (Body)
};

// An affine map q -> R^3.
struct AffineVector {
  Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, kMaxConstrainedDofs> linear;
  Vec3 offset = Vec3::Zero();
};

// Joint kinds and the number of scalar constraints each imposes. A planar joint keeps b's
// directions perpendicular to a's axis (the plane normal: 2 constraints) and b's anchor point in
// a's plane through the anchor (1 constraint): b slides in the plane and turns about the normal.
enum class JointType { Spherical, Revolute, Universal, Cylindrical, Prismatic, Fixed, Distance, Planar };
inline constexpr const char* kJointTypeNames =
    "spherical, revolute, universal, cylindrical, prismatic, fixed, distance, planar";
std::optional<JointType> jointTypeByName(const std::string& name);
int constraintCount(JointType type);
// Whether the first three forms of JointBuilder::joint(type, ...) are the x, y and z components
// of the gap between the two anchor points: one spatial vector, and so are their multipliers.
bool coincidesPoints(JointType type);

struct JointGeometry {
  Vec3 anchor = Vec3::Zero();   // joint point (world, t = 0); on b for a distance joint: anchorB
  Vec3 anchorB = Vec3::Zero();  // distance joint: the point on b
  Vec3 axis = Vec3::UnitZ();    // unit; revolute/cylindrical/prismatic axis, planar normal, universal axis on a
  Vec3 axisB = Vec3::UnitX();   // universal: axis on b, perpendicular to axis
};

class JointBuilder {
 public:
  JointBuilder(const Attachment& a, const Attachment& b);
  // The rigidity of one body: a constraint within it, not between two things.
  explicit JointBuilder(const Attachment& body);

  // What the forms join: the first position dof of each side (-1: the ground), the same dof
  // twice for a body's rigidity.
  std::pair<int, int> ends() const { return ends_; }

  // The position dofs q of the forms, a's then b's.
  const std::vector<int>& positionDofs() const { return dofs_; }
  // Forms of a joint; throws std::invalid_argument when the attachments cannot carry it.
  std::vector<QuadraticForm> joint(JointType type, const JointGeometry& geometry) const;
  // d_i . d_j - delta_ij of a single body (the one-body builder).
  std::vector<QuadraticForm> rigidity() const;
  // Quadratic invariants that give a joint's coordinate: revolute (u, v) = (a1.b1, a2.b1) with
  // a1, a2 perpendicular to the axis on a and b1 on b (angle atan2(v, u), 0 at t = 0);
  // prismatic s = (p_b - p_a).axis_a - s(0) (0 at t = 0); spherical (bushing) the three
  // components of sin(psi) n, psi n the relative rotation (0 at t = 0). Throws for other types.
  std::vector<QuadraticForm> coordinateInvariants(JointType type, const JointGeometry& geometry) const;

 private:
  AffineVector point(int side, const Vec3& worldPoint) const;
  AffineVector direction(int side, const Vec3& worldDirection) const;
  QuadraticForm component(const AffineVector& v, int k) const;
  QuadraticForm dot(const AffineVector& u, const AffineVector& v, double target) const;
  // u(q).v(q) as 1/2 q.H q + g.q + c
  struct DenseQuadratic {
    ConstraintMatrix hessian;
    ConstraintVector gradient;
    double constant;
  };
  static DenseQuadratic product(const AffineVector& u, const AffineVector& v);
  AffineVector difference(const AffineVector& u, const AffineVector& v) const;

  Attachment sides_[2];
  int offset_[2] = {0, 0};  // first local q index of each side
  std::vector<int> dofs_;
  std::pair<int, int> ends_;
};

}  // namespace mpx
