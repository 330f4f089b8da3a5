#include "engine/core/model.hpp"

#include <algorithm>
#include <cmath>

namespace mpx {

Model::Model(Layout layout, ThermalVariable thermalVariable, std::vector<std::unique_ptr<Component>> components,
             std::vector<std::string> thermalNodeNames, Eigen::VectorXd initialState, Eigen::VectorXd dofScale,
             std::vector<PrescribedMotion> prescribedMotions, std::vector<double> loadBreakpoints)
    : layout_(layout),
      thermalVariable_(thermalVariable),
      components_(std::move(components)),
      thermalNodeNames_(std::move(thermalNodeNames)),
      initialState_(std::move(initialState)),
      dofScale_(std::move(dofScale)),
      prescribedMotions_(std::move(prescribedMotions)),
      loadBreakpoints_(std::move(loadBreakpoints)) {
  std::sort(loadBreakpoints_.begin(), loadBreakpoints_.end());
  loadBreakpoints_.erase(std::unique(loadBreakpoints_.begin(), loadBreakpoints_.end()), loadBreakpoints_.end());
  // couplings read what the others publish: evaluate them last
  std::stable_partition(components_.begin(), components_.end(),
                        [](const std::unique_ptr<Component>& c) { return !c->isCoupling(); });
  for (std::size_t i = 0; i < components_.size(); ++i) components_[i]->modelIndex_ = static_cast<int>(i);
}

double Model::nextLoadBreakpoint(double t) const {
  const auto next = std::upper_bound(loadBreakpoints_.begin(), loadBreakpoints_.end(), t);
  return next == loadBreakpoints_.end() ? INFINITY : *next;
}

void Model::measure(const Eigen::VectorXd& z, Measures& out) const {
  out.energy = out.entropy = out.constraintViolation = 0.0;
  out.momentum.setZero();
  out.angularMomentum.setZero();
  out.nodeTemperature.assign(thermalNodeNames_.size(), 0.0);
  for (const auto& component : components_) component->measure(z.data(), out);
}

Workspace Model::makeWorkspace() const {
  Workspace ws;
  ws.nodes.resize(thermalNodeNames_.size());
  for (const auto& component : components_) ws.stageScratch.push_back(component->makeStageScratch());
  return ws;
}

}  // namespace mpx
