#include "tools/output/history_csv.hpp"

#include "engine/core/input_error.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace mpx {

HistoryCsv::HistoryCsv(const std::filesystem::path& directory, const CompiledScene& scene)
    : columns_(scene), partPath_(directory / "history.csv.part"), finalPath_(directory / "history.csv") {
  file_ = std::fopen(partPath_.c_str(), "w");
  if (!file_) throw InputError(partPath_.string() + ": cannot create the output file");
  fmt::print(file_, "{}\n", fmt::join(columns_.names(), ","));
}

HistoryCsv::~HistoryCsv() {
  if (file_) std::fclose(file_);
}

void HistoryCsv::write(const StepRecord& r) {
  columns_.values(r, values_);
  fmt::print(file_, "{:.17g}\n", fmt::join(values_, ","));
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
