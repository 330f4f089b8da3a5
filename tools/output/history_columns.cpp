#include "tools/output/history_columns.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace mpx {

HistoryColumns::HistoryColumns(const CompiledScene& scene)
    : names_{"time",
             "dt",
             "energy",
             "entropy",
             "dissipated_energy",
             "external_work",
             "boundary_heat",
             "boundary_entropy",
             "entropy_production",
             "momentum_x",
             "momentum_y",
             "momentum_z",
             "angular_momentum_x",
             "angular_momentum_y",
             "angular_momentum_z",
             "newton_iterations",
             "cutbacks",
             "constraint_violation"} {
  for (const std::string& node : scene.model->thermalNodeNames()) names_.push_back("temperature_" + node);
  for (const SolidPlacement& solid : scene.solids) {
    if (solid.thermalDofs.empty()) continue;
    thermalSolids_.push_back(&solid);
    for (const char* statistic : {"min", "max", "mean"})
      names_.push_back(fmt::format("temperature_{}_{}", statistic, solid.name));
  }
}

void HistoryColumns::values(const StepRecord& r, std::vector<double>& out) const {
  const Measures& m = *r.measures;
  out.assign({r.time, r.dt, m.energy, m.entropy, r.crossed.dissipated, r.crossed.externalWork, r.crossed.boundaryHeat,
              r.crossed.boundaryEntropy, m.entropy - r.initialEntropy - r.crossed.boundaryEntropy, m.momentum.x(),
              m.momentum.y(), m.momentum.z(), m.angularMomentum.x(), m.angularMomentum.y(), m.angularMomentum.z(),
              static_cast<double>(r.newtonIterations), static_cast<double>(r.cutbacks), m.constraintViolation});
  out.insert(out.end(), m.nodeTemperature.begin(), m.nodeTemperature.end());
  // a thermal solid's range over its nodes
  for (const SolidPlacement* solid : thermalSolids_) {
    double low = INFINITY, high = -INFINITY, sum = 0.0;
    const int nodes = static_cast<int>(solid->thermalDofs.size());
    for (int n = 0; n < nodes; ++n) {
      const double theta = solid->nodeTemperature(r.state->data(), n);
      low = std::min(low, theta);
      high = std::max(high, theta);
      sum += theta;
    }
    out.insert(out.end(), {low, high, sum / nodes});
  }
}

}  // namespace mpx
