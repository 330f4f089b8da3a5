#pragma once
// The coordinate of a revolute or prismatic joint from its quadratic invariants
// (JointBuilder::coordinateInvariants): an angle atan2(v, u) or a displacement s, both zero at
// t = 0. Shared by the joint force elements and the joints.csv output.
#include "models/multibody/quadratic_constraint.hpp"

#include "engine/core/discrete_gradient.hpp"

namespace mpx {

// The coordinate near `centre` as a smooth function of the invariants (value, gradient,
// Hessian): a revolute angle is measured from the centre's direction, so there is no
// wrap-around for increments below pi; a prismatic coordinate is s itself.
Jet jointCoordinateChart(bool revolute, const Vec3& invariants, const Vec3& centre);

// Reads a joint's coordinate and rate from states, unwrapping angles across calls.
class JointCoordinate {
 public:
  JointCoordinate(std::string name, bool revolute, std::vector<int> positionDofs, int velocityShift,
                  std::vector<QuadraticForm> invariants, double offset);

  const std::string& name() const { return name_; }
  // Coordinate (plus the offset to the user's zero) continued from `previous`.
  double position(const double* z, double previous) const;
  double velocity(const double* z) const;
  double initialPosition() const { return offset_; }

 private:
  ConstraintVector gather(const double* z, int shift) const;
  Vec3 invariantsAt(const ConstraintVector& q) const;

  std::string name_;
  bool revolute_;
  std::vector<int> positionDofs_;
  int velocityShift_;
  std::vector<QuadraticForm> invariants_;
  double offset_;
};

}  // namespace mpx
