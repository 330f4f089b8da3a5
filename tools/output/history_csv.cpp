#include "tools/output/history_csv.hpp"

#include "engine/core/input_error.hpp"

#include <fmt/format.h>

namespace mpx {

HistoryCsv::HistoryCsv(const std::filesystem::path& directory, const CompiledScene& scene)
    : partPath_(directory / "history.csv.part"), finalPath_(directory / "history.csv") {
  file_ = std::fopen(partPath_.c_str(), "w");
  if (!file_) throw InputError(partPath_.string() + ": cannot create the output file");
  std::string header =
      "time,dt,energy,entropy,dissipated_energy,external_work,boundary_heat,boundary_entropy,entropy_production,"
      "momentum_x,momentum_y,momentum_z,angular_momentum_x,angular_momentum_y,angular_momentum_z,newton_iterations,"
      "cutbacks,constraint_violation";
  for (const std::string& node : scene.model->thermalNodeNames()) header += ",temperature_" + node;
  for (const SolidPlacement& solid : scene.solids) {
    if (solid.thermalDofs.empty()) continue;
    thermalSolids_.push_back(&solid);
    for (const char* statistic : {"min", "max", "mean"})
      header += fmt::format(",temperature_{}_{}", statistic, solid.name);
  }
  fmt::print(file_, "{}\n", header);
}

HistoryCsv::~HistoryCsv() {
  if (file_) std::fclose(file_);
}

void HistoryCsv::write(const StepRecord& r) {
  const Measures& m = *r.measures;
  fmt::print(
      file_,
      "{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:."
      "17g},{:.17g},{},{},{:.17g}",
      r.time, r.dt, m.energy, m.entropy, r.crossed.dissipated, r.crossed.externalWork, r.crossed.boundaryHeat,
      r.crossed.boundaryEntropy, m.entropy - r.initialEntropy - r.crossed.boundaryEntropy, m.momentum.x(),
      m.momentum.y(), m.momentum.z(), m.angularMomentum.x(), m.angularMomentum.y(), m.angularMomentum.z(),
      r.newtonIterations, r.cutbacks, m.constraintViolation);
  for (double temperature : m.nodeTemperature) fmt::print(file_, ",{:.17g}", temperature);
  for (const SolidPlacement* solid : thermalSolids_) {
    double low = INFINITY, high = -INFINITY, sum = 0.0;
    const int nodes = static_cast<int>(solid->thermalDofs.size());
    for (int n = 0; n < nodes; ++n) {
      const double theta = solid->nodeTemperature(r.state->data(), n);
      low = std::min(low, theta);
      high = std::max(high, theta);
      sum += theta;
    }
    fmt::print(file_, ",{:.17g},{:.17g},{:.17g}", low, high, sum / nodes);
  }
  std::fputc('\n', file_);
}

void HistoryCsv::finish(const RunSummary& summary) {
  if (summary.failed)
    fmt::print(file_, "# solver failure at step {} (t = {:.17g}): {}; rows above are the last good steps\n",
               summary.failedStep, summary.failedTime, summary.failure);
  if (summary.interrupted)
    fmt::print(file_, "# interrupted after step {} (t = {:.17g}) by a stop request (SIGINT or SIGTERM)\n",
               summary.steps, summary.interruptedTime);
  std::fclose(file_);
  file_ = nullptr;
  std::filesystem::rename(partPath_, finalPath_);
}

}  // namespace mpx
