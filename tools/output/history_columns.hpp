#pragma once
// The columns of a run's history, one value per step: time and step, the balance terms
// (energy, entropy, dissipated energy, external work, boundary heat and entropy, entropy
// production = the entropy change not brought in through boundaries), momenta, Newton counts,
// constraint violation, node temperatures and each thermal solid's temperature range. One
// definition for DIR/history.csv and the Python module's in-memory history.
#include "engine/stepping/simulation.hpp"
#include "models/scene/scene_loader.hpp"

#include <string>
#include <vector>

namespace mpx {

class HistoryColumns {
 public:
  // `scene` must outlive the columns.
  explicit HistoryColumns(const CompiledScene& scene);
  const std::vector<std::string>& names() const { return names_; }
  // One value per name, in order, into `values` (resized once, then reused).
  void values(const StepRecord& record, std::vector<double>& values) const;

 private:
  std::vector<std::string> names_;
  std::vector<const SolidPlacement*> thermalSolids_;
};

}  // namespace mpx
