#include "tools/output/frame_sampler.hpp"

namespace mpx {

FrameSampler::FrameSampler(const CompiledScene& scene)
    : scene_(scene), bodies_(scene.bodies.size()), joints_(scene.joints.size()) {
  for (std::size_t j = 0; j < joints_.size(); ++j) joints_[j].position = scene.joints[j].initialPosition();
}

void FrameSampler::sample(const double* z) {
  // a body's directors, times the fixed map to its body frame, are its rotation
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const BodyFrame& body = scene_.bodies[b];
    Eigen::Matrix3d directors;
    for (int i = 0; i < 3; ++i) directors.col(i) = Eigen::Map<const Vec3>(z + body.firstPositionDof + 3 + 3 * i);
    bodies_[b].position = Eigen::Map<const Vec3>(z + body.firstPositionDof);
    bodies_[b].orientation = Eigen::Quaterniond(directors * body.directorsToBody);
  }
  for (std::size_t j = 0; j < joints_.size(); ++j) {
    joints_[j].position = scene_.joints[j].position(z, joints_[j].position);
    joints_[j].velocity = scene_.joints[j].velocity(z);
  }
}

}  // namespace mpx
