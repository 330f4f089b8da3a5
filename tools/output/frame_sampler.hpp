#pragma once
// Rigid-body poses (centre of mass, orientation quaternion) and joint coordinates (position,
// velocity) of a state, for DIR/bodies.csv, DIR/joints.csv and the Python module's frames.
// Revolute joint angles are unwrapped against the previous sample, so they run past +-pi.
#include "models/scene/scene_loader.hpp"

#include <Eigen/Geometry>
#include <vector>

namespace mpx {

struct BodyPose {
  Vec3 position;
  Eigen::Quaterniond orientation;
};

struct JointSample {
  double position = 0.0, velocity = 0.0;
};

class FrameSampler {
 public:
  // `scene` must outlive the sampler.
  explicit FrameSampler(const CompiledScene& scene);
  // Poses and joint coordinates of state z, in the scene's order of bodies and joints.
  void sample(const double* z);
  const std::vector<BodyPose>& bodies() const { return bodies_; }
  const std::vector<JointSample>& joints() const { return joints_; }

 private:
  const CompiledScene& scene_;
  std::vector<BodyPose> bodies_;
  std::vector<JointSample> joints_;
};

}  // namespace mpx
