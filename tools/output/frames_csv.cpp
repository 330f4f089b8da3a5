#include "tools/output/frames_csv.hpp"

#include "engine/core/input_error.hpp"

#include <fmt/format.h>

namespace mpx {

FramesCsv::FramesCsv(const std::filesystem::path& directory, const CompiledScene& scene, double interval)
    : scene_(scene), schedule_(interval) {
  if (!scene.bodies.empty()) open(bodies_, directory / "bodies.csv", "time,body,x,y,z,qw,qx,qy,qz");
  if (!scene.joints.empty()) open(joints_, directory / "joints.csv", "time,joint,position,velocity");
  for (const JointCoordinate& joint : scene.joints) jointPositions_.push_back(joint.initialPosition());
}

FramesCsv::~FramesCsv() {
  for (Output* output : {&bodies_, &joints_})
    if (output->file) std::fclose(output->file);
}

void FramesCsv::open(Output& output, const std::filesystem::path& path, const char* header) {
  output.final = path;
  output.part = path.string() + ".part";
  output.file = std::fopen(output.part.c_str(), "w");
  if (!output.file) throw InputError(output.part.string() + ": cannot create the output file");
  fmt::print(output.file, "{}\n", header);
}

void FramesCsv::write(const StepRecord& record) {
  if (!schedule_.due(record.time)) return;
  const double* z = record.state->data();
  for (const BodyFrame& body : scene_.bodies) {
    Eigen::Matrix3d directors;
    for (int i = 0; i < 3; ++i) directors.col(i) = Eigen::Map<const Vec3>(z + body.firstPositionDof + 3 + 3 * i);
    const Eigen::Quaterniond q(directors * body.directorsToBody);
    fmt::print(bodies_.file, "{:.17g},{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}\n", record.time,
               body.name, z[body.firstPositionDof], z[body.firstPositionDof + 1], z[body.firstPositionDof + 2], q.w(),
               q.x(), q.y(), q.z());
  }
  for (std::size_t j = 0; j < scene_.joints.size(); ++j) {
    jointPositions_[j] = scene_.joints[j].position(z, jointPositions_[j]);
    fmt::print(joints_.file, "{:.17g},{},{:.17g},{:.17g}\n", record.time, scene_.joints[j].name(), jointPositions_[j],
               scene_.joints[j].velocity(z));
  }
}

void FramesCsv::finish() {
  for (Output* output : {&bodies_, &joints_}) {
    if (!output->file) continue;
    std::fclose(output->file);
    output->file = nullptr;
    std::filesystem::rename(output->part, output->final);
  }
}

}  // namespace mpx
