#pragma once
// Where the energy went, per scene element: each element's stored energy and entropy, and the
// dissipated energy, external work, boundary heat and boundary entropy its components
// reported since t = 0, with its entropy production (its entropy change not brought in
// through the boundary). The prescribed motions' reactions form one more group. Summed over
// the groups, each column is history.csv's total (DIR/budget.csv, the Python module's budget).
#include "engine/stepping/simulation.hpp"
#include "models/scene/scene_loader.hpp"

#include <array>
#include <string>
#include <vector>

namespace mpx {

class ElementBudget {
 public:
  static constexpr int kColumns = 7;
  using Row = std::array<double, kColumns>;
  // energy, entropy, dissipated_energy, external_work, boundary_heat, boundary_entropy,
  // entropy_production: history.csv's names
  static const std::array<const char*, kColumns>& columnNames();

  // `scene` must outlive the budget.
  explicit ElementBudget(const CompiledScene& scene);
  // The groups: the scene's elements in order, then "prescribed_motions" if it has any.
  const std::vector<std::string>& groups() const { return groups_; }
  // One row per group for a record of a run that kept its flows per component.
  const std::vector<Row>& rows(const StepRecord& record);

 private:
  const Model& model_;
  std::vector<std::string> groups_;
  std::vector<int> groupOf_;  // per component, then the prescribed motions' entry (-1: none)
  std::vector<double> initialEntropy_;
  std::vector<Row> rows_;
  Measures own_;
};

}  // namespace mpx
