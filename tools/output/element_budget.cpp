#include "tools/output/element_budget.hpp"

#include <algorithm>
#include <stdexcept>

namespace mpx {

namespace {

enum Column { kEnergy, kEntropy, kDissipated, kExternalWork, kBoundaryHeat, kBoundaryEntropy, kProduction };

}  // namespace

const std::array<const char*, ElementBudget::kColumns>& ElementBudget::columnNames() {
  static const std::array<const char*, kColumns> names = {
      "energy",        "entropy",          "dissipated_energy", "external_work",
      "boundary_heat", "boundary_entropy", "entropy_production"};
  return names;
}

ElementBudget::ElementBudget(const CompiledScene& scene) : model_(*scene.model) {
  // groups in the order the scene names them
  for (const std::string& element : scene.componentElements) {
    auto known = std::find(groups_.begin(), groups_.end(), element);
    groupOf_.push_back(static_cast<int>(known - groups_.begin()));
    if (known == groups_.end()) groups_.push_back(element);
  }
  if (!model_.prescribedMotions().empty()) groups_.push_back("prescribed_motions");
  groupOf_.push_back(model_.prescribedMotions().empty() ? -1 : static_cast<int>(groups_.size()) - 1);
  rows_.assign(groups_.size(), Row{});
  own_.nodeTemperature.assign(model_.thermalNodeNames().size(), 0.0);
  // entropy production counts from each group's entropy at t = 0
  initialEntropy_.assign(groups_.size(), 0.0);
  const auto& components = model_.components();
  for (std::size_t c = 0; c < components.size(); ++c) {
    own_.entropy = 0.0;
    components[c]->measure(model_.initialState().data(), own_);
    initialEntropy_[groupOf_[c]] += own_.entropy;
  }
}

const std::vector<ElementBudget::Row>& ElementBudget::rows(const StepRecord& record) {
  // the initial record comes before any step, when nothing has crossed yet
  if (!record.componentCrossed && record.step > 0)
    throw std::logic_error("ElementBudget: the run kept no flows per component");
  std::fill(rows_.begin(), rows_.end(), Row{});
  const auto& components = model_.components();
  for (std::size_t c = 0; c < components.size(); ++c) {
    own_.energy = own_.entropy = 0.0;
    components[c]->measure(record.state->data(), own_);
    rows_[groupOf_[c]][kEnergy] += own_.energy;
    rows_[groupOf_[c]][kEntropy] += own_.entropy;
  }
  if (record.componentCrossed)
    for (std::size_t c = 0; c < record.componentCrossed->size(); ++c) {
      if (groupOf_[c] < 0) continue;  // no prescribed motions, no reactions
      const Flows& crossed = (*record.componentCrossed)[c];
      Row& row = rows_[groupOf_[c]];
      row[kDissipated] += crossed.dissipated;
      row[kExternalWork] += crossed.externalWork;
      row[kBoundaryHeat] += crossed.boundaryHeat;
      row[kBoundaryEntropy] += crossed.boundaryEntropy;
    }
  for (std::size_t g = 0; g < rows_.size(); ++g)
    rows_[g][kProduction] = rows_[g][kEntropy] - initialEntropy_[g] - rows_[g][kBoundaryEntropy];
  return rows_;
}

}  // namespace mpx
