#include "models/thermal/heat_link.hpp"

#include <algorithm>
#include <cassert>

namespace mpx {

std::vector<int> HeatLink::unionDofs(const ThermalNodeRef& a, const ThermalNodeRef& b) {
  std::vector<int> dofs = a.ownerDofs;
  for (int dof : b.ownerDofs)
    if (std::find(dofs.begin(), dofs.end(), dof) == dofs.end()) dofs.push_back(dof);
  return dofs;
}

int HeatLink::localIndex(int globalDof) const {
  const auto& list = dofs();
  return static_cast<int>(std::find(list.begin(), list.end(), globalDof) - list.begin());
}

HeatLink::HeatLink(std::string name, ThermalNodeRef a, ThermalNodeRef b, double conductivity)
    : Component(std::move(name), unionDofs(a, b)), ends_{std::move(a), std::move(b)}, conductivity_(conductivity) {
  temperatureColumn_.assign(dofs().size(), false);
  for (int e = 0; e < 2; ++e) {
    assert(ends_[e].ownerVelocity.size() == ends_[e].ownerDofs.size());
    for (std::size_t k = 0; k < ends_[e].ownerDofs.size(); ++k) {
      ownerToLocal_[e].push_back(localIndex(ends_[e].ownerDofs[k]));
      if (!ends_[e].ownerVelocity[k]) temperatureColumn_[ownerToLocal_[e].back()] = true;
    }
    if (ends_[e].thermalDof >= 0) localThermal_[e] = localIndex(ends_[e].thermalDof);
  }
}

void HeatLink::measure(const double*, Measures&) const {}

void HeatLink::exchange(const Workspace& ws, LocalSystem& out, Flows& flows) const {
  const NodeTemperature* node[2] = {&ws.nodes[ends_[0].node], &ws.nodes[ends_[1].node]};
  auto r = out.residual();
  auto K = out.tangent();
  for (int e = 0; e < 2; ++e) {
    const int other = 1 - e;
    const double heatIn = conductivity_ * (node[other]->value - node[e]->value);
    // heat through a prescribed temperature crosses the system boundary
    if (localThermal_[e] < 0) {
      flows.boundaryHeat -= heatIn;
      flows.boundaryEntropy -= heatIn / node[e]->value;
      continue;
    }
    r[localThermal_[e]] -= heatIn;
    for (int k = 0; k < node[other]->count; ++k)
      K(localThermal_[e], ownerToLocal_[other][k]) -= conductivity_ * node[other]->grad[k];
    for (int k = 0; k < node[e]->count; ++k)
      K(localThermal_[e], ownerToLocal_[e][k]) += conductivity_ * node[e]->grad[k];
  }
}

void HeatLink::eemLocal(const StepArgs&, Workspace& ws, LocalSystem& out, Flows& flows) const {
  exchange(ws, out, flows);
}

void HeatLink::rateLocal(const RateArgs&, Workspace& ws, LocalSystem& out, Flows& flows) const {
  exchange(ws, out, flows);
}

}  // namespace mpx
