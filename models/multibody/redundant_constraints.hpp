#pragma once
// Redundant constraint conditions. A closed loop of joints can impose more conditions than
// it removes freedoms: a planar loop of 3D revolute joints repeats its out-of-plane
// conditions (a four-bar gives 20 + 18 rigidity conditions on 36 coordinates of a 1-dof
// mechanism). The gradients of such conditions are linearly dependent, and the
// augmented-Lagrangian saddle point is singular. At set-up, a rank-revealing sparse QR of the
// gradients at the initial configuration, in declaration order, finds each condition whose
// gradient is a combination of those declared before it; its multipliers are held at zero.
// The kept conditions still imply it, so it stays satisfied (and is still measured). Only
// mechanisms with a closed loop can be redundant (a tree's joints are independent, as their
// degenerate geometries are refused at input), so only they are factorised: a 20 000-link
// URDF chain costs nothing here.
#include "models/multibody/quadratic_constraint.hpp"

#include <string>
#include <vector>

namespace mpx {

// The conditions of one constraint set (a joint, or a body's rigidity) found redundant.
struct RedundantConditions {
  std::string constraint;
  std::vector<std::size_t> forms;  // their indices among the set's forms
  std::size_t formCount;
};

// A constraint set and what it joins: the first position dof of each end (-1: the ground,
// one node for all anchors), the same dof twice for a body's own rigidity.
struct ConstraintEdge {
  QuadraticConstraint* constraint;
  std::pair<int, int> ends;
};

// Finds the redundant conditions among the augmented-Lagrangian constraints at state z, holds
// their multipliers at zero and returns them, constraint sets in declaration order.
std::vector<RedundantConditions> holdRedundantMultipliers(const std::vector<ConstraintEdge>& constraints,
                                                          const Eigen::VectorXd& z);

// "joint 'a' (2 of 5), ..." for a message.
std::string describeRedundancy(const std::vector<RedundantConditions>& redundant);

}  // namespace mpx
