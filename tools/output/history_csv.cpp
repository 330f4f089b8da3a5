#include "tools/output/history_csv.hpp"

#include "engine/core/input_error.hpp"

#include <fmt/format.h>

namespace mpx {

HistoryCsv::HistoryCsv(const std::filesystem::path& directory, const Model& model)
    : partPath_(directory / "history.csv.part"), finalPath_(directory / "history.csv") {
  file_ = std::fopen(partPath_.c_str(), "w");
  if (!file_) throw InputError(partPath_.string() + ": cannot create the output file");
  std::string header =
      "time,dt,energy,entropy,dissipated_energy,external_work,boundary_heat,momentum_x,momentum_y,momentum_z,"
      "angular_momentum_x,angular_momentum_y,angular_momentum_z,newton_iterations,cutbacks,constraint_violation";
  for (const std::string& node : model.thermalNodeNames()) header += ",temperature_" + node;
  fmt::print(file_, "{}\n", header);
}

HistoryCsv::~HistoryCsv() {
  if (file_) std::fclose(file_);
}

void HistoryCsv::write(const StepRecord& r) {
  const Measures& m = *r.measures;
  fmt::print(
      file_,
      "{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{},{},"
      "{:.17g}",
      r.time, r.dt, m.energy, m.entropy, r.crossed.dissipated, r.crossed.externalWork, r.crossed.boundaryHeat,
      m.momentum.x(), m.momentum.y(), m.momentum.z(), m.angularMomentum.x(), m.angularMomentum.y(),
      m.angularMomentum.z(), r.newtonIterations, r.cutbacks, m.constraintViolation);
  for (double temperature : m.nodeTemperature) fmt::print(file_, ",{:.17g}", temperature);
  std::fputc('\n', file_);
}

void HistoryCsv::finish(const RunSummary& summary) {
  if (summary.failed)
    fmt::print(file_, "# solver failure at step {} (t = {:.17g}): {}; rows above are the last good steps\n",
               summary.failedStep, summary.failedTime, summary.failure);
  std::fclose(file_);
  file_ = nullptr;
  std::filesystem::rename(partPath_, finalPath_);
}

}  // namespace mpx
