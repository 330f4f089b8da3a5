#pragma once
// PNG plots of a work-precision study, rendered by gnuplot (a Debian package, installed by
// tools/install-deps.sh): error against CPU time (final state, and the energy at the end of
// loading where the scene has loads), energy error and entropy against time.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace mpx {

struct WorkPrecisionPoint {
  double cpu, error, energyError;  // energyError NaN: not measured
};

struct WorkPrecisionCurve {
  std::string label;
  std::vector<WorkPrecisionPoint> points;
};

struct SeriesPoint {
  double time, energyError, entropyChange;
};

struct TimeSeries {
  std::string label;
  std::vector<SeriesPoint> points;
};

// Writes DIR/plot_data/*, DIR/plots.gp and renders DIR/work_precision.png, energy_error.png,
// entropy.png, and work_precision_energy.png when energy errors were measured. Throws
// std::runtime_error when gnuplot fails.
void renderPlots(const std::filesystem::path& dir, const std::string& sceneName, double tEnd,
                 const std::vector<WorkPrecisionCurve>& workPrecision, const std::vector<TimeSeries>& series);

}  // namespace mpx
