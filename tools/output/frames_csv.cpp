#include "tools/output/frames_csv.hpp"

#include "engine/core/input_error.hpp"

#include <fmt/format.h>

namespace mpx {

FramesCsv::FramesCsv(const std::filesystem::path& directory, const CompiledScene& scene, double interval)
    : scene_(scene), schedule_(interval), sampler_(scene) {
  if (!scene.bodies.empty()) open(bodies_, directory / "bodies.csv", "time,body,x,y,z,qw,qx,qy,qz");
  if (!scene.joints.empty()) open(joints_, directory / "joints.csv", "time,joint,position,velocity");
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
  sampler_.sample(record.state->data());
  for (std::size_t b = 0; b < scene_.bodies.size(); ++b) {
    const BodyPose& pose = sampler_.bodies()[b];
    const Eigen::Quaterniond& q = pose.orientation;
    fmt::print(bodies_.file, "{:.17g},{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}\n", record.time,
               scene_.bodies[b].name, pose.position.x(), pose.position.y(), pose.position.z(), q.w(), q.x(), q.y(),
               q.z());
  }
  for (std::size_t j = 0; j < scene_.joints.size(); ++j)
    fmt::print(joints_.file, "{:.17g},{},{:.17g},{:.17g}\n", record.time, scene_.joints[j].name(),
               sampler_.joints()[j].position, sampler_.joints()[j].velocity);
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
