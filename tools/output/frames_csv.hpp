#pragma once
// DIR/bodies.csv (time, body, x, y, z, qw, qx, qy, qz) and DIR/joints.csv (time, joint,
// position, velocity) for scenes with rigid bodies or revolute/prismatic joints, one row per
// output time and body or joint. Written as .part files and renamed when the run ends.
#include "engine/stepping/simulation.hpp"
#include "models/scene/scene_loader.hpp"
#include "tools/output/frame_sampler.hpp"
#include "tools/output/output_schedule.hpp"

#include <cstdio>
#include <filesystem>

namespace mpx {

class FramesCsv {
 public:
  // interval <= 0: every step.
  FramesCsv(const std::filesystem::path& directory, const CompiledScene& scene, double interval);
  ~FramesCsv();
  FramesCsv(const FramesCsv&) = delete;
  FramesCsv& operator=(const FramesCsv&) = delete;

  void write(const StepRecord& record);
  void finish();

 private:
  struct Output {
    std::FILE* file = nullptr;
    std::filesystem::path part, final;
  };
  void open(Output& output, const std::filesystem::path& path, const char* header);

  const CompiledScene& scene_;
  OutputSchedule schedule_;
  FrameSampler sampler_;
  Output bodies_, joints_;
};

}  // namespace mpx
