#pragma once
// ParaView output of the finite-element solids of a run: DIR/<solid>.pvd listing
// DIR/<solid>/frame_<k>.vtu (displacement, velocity and, for a thermal solid, temperature at
// nodes; Cauchy stress, von Mises stress, viscous strain and heat flux per cell), one frame per
// output interval, and at the end a picture of the last frame, DIR/<solid>.png, coloured by
// the temperature of a thermal solid or else by the von Mises stress.
#include "engine/stepping/simulation.hpp"
#include "models/scene/scene_loader.hpp"
#include "tools/output/output_schedule.hpp"
#include "tools/output/vtk_writer.hpp"

#include <filesystem>

namespace mpx {

class SolidFrames {
 public:
  // interval <= 0: every step.
  SolidFrames(const std::filesystem::path& directory, const CompiledScene& scene, double interval);

  void write(const StepRecord& record);
  // Render the last frame of each solid (a warning, not an error, if gnuplot fails).
  void finish();

 private:
  struct Series {
    const SolidPlacement* solid;
    PvdSeries pvd;
    std::vector<Vec3> positions;  // of the last frame written
    std::vector<double> picture;  // the last frame's cell values the picture is coloured by
    double time = 0.0;
  };
  std::filesystem::path directory_;
  double interval_;
  OutputSchedule schedule_;
  int frame_ = -1;  // the last frame written
  std::vector<Series> series_;
};

}  // namespace mpx
