#pragma once
// URDF front end of the scene format (docs/scene-format.md, "URDF robots"): a robot read with
// urdfdom becomes the scene elements that describe it, in world coordinates at the initial
// configuration: an <anchor> for the ground, a <body> per link with mass, a <joint> per moving
// or fixed URDF joint and a joint damper per joint with <dynamics>. The scene compiler then
// reads them like hand-written elements.
#include "engine/core/component.hpp"
#include "models/scene/scene_spec.hpp"

#include <map>
#include <string>

namespace mpx {

// Initial coordinate and rate of a revolute, continuous or prismatic joint (rad or m, per s).
struct UrdfJointState {
  double position = 0.0;
  double velocity = 0.0;
};

struct UrdfImportOptions {
  bool floating = false;         // the root link moves freely instead of being fixed to the ground
  Vec3 position = Vec3::Zero();  // world pose of the root link's frame
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  std::map<std::string, UrdfJointState> initial;  // by URDF joint name; the others start at 0, at rest
  std::string prefix;                             // put before every element name, so a robot can be included twice
  // raise principal moments that violate the strict triangle inequality (with a warning) instead of failing
  bool balanceInertia = false;
  // stops at the position limits of revolute and prismatic joints (a <joint_force> NAME.limits each)
  bool limits = false;
  double limitStiffness = 1e4;  // k_s of the stops (N m/rad^2 or N/m^2)
  double limitDamping = 5e3;    // c_s of the stops (N m s/rad^3 or N s/m^3)
};

// Validate the URDF at `path` and append its scene elements to `scene`, in an order the
// compiler accepts (every reference declared above its use); each element's location is the
// URDF line of the <link> or <joint> it comes from. Throws InputError naming the URDF file
// and, where there is one, the line of the offending <link> or <joint>.
void appendUrdfElements(const std::string& path, const UrdfImportOptions& options, SceneSpec& scene);

}  // namespace mpx
