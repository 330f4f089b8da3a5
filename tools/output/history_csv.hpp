#pragma once
// DIR/history.csv: one row per step. Written to history.csv.part and renamed when the run
// ends, so an interrupted run never leaves a file that looks complete; a solver failure is
// kept up to the last good step and marked by a final comment line. Columns: HistoryColumns.
#include "tools/output/history_columns.hpp"

#include <cstdio>
#include <filesystem>
#include <string>

namespace mpx {

class HistoryCsv {
 public:
  // `scene` must outlive the writer.
  HistoryCsv(const std::filesystem::path& directory, const CompiledScene& scene);
  ~HistoryCsv();
  HistoryCsv(const HistoryCsv&) = delete;
  HistoryCsv& operator=(const HistoryCsv&) = delete;

  void write(const StepRecord& record);
  // Close and publish the file; a failed run gets its failure line first.
  void finish(const RunSummary& summary);
  std::filesystem::path path() const { return finalPath_; }

 private:
  HistoryColumns columns_;
  std::vector<double> values_;
  std::FILE* file_ = nullptr;
  std::filesystem::path partPath_, finalPath_;
};

}  // namespace mpx
