#include "models/thermal/surface_heat_link.hpp"

#include <algorithm>
#include <cassert>

namespace mpx {

// the solid node's dof first, then the dofs the lumped node's published temperature depends on
std::vector<int> SurfaceHeatLink::collectDofs(int solidThermalDof, const ThermalNodeRef& node) {
  std::vector<int> dofs = {solidThermalDof};
  dofs.insert(dofs.end(), node.ownerDofs.begin(), node.ownerDofs.end());
  return dofs;
}

SurfaceHeatLink::SurfaceHeatLink(std::string name, int solidThermalDof, NodalThermalVariable thermalVariable,
                                 ThermalNodeRef node, double conductance)
    : Component(std::move(name), collectDofs(solidThermalDof, node)),
      thermalVariable_(thermalVariable),
      node_(std::move(node)),
      conductance_(conductance) {
  assert(node_.ownerVelocity.size() == node_.ownerDofs.size());
  if (node_.thermalDof >= 0)
    lumpedRow_ = static_cast<int>(std::find(dofs().begin(), dofs().end(), node_.thermalDof) - dofs().begin());
}

void SurfaceHeatLink::exchange(double T, double slope, const Workspace& ws, LocalSystem& out, Flows& flows) const {
  const NodeTemperature& lumped = ws.nodes[node_.node];
  const double heat = conductance_ * (lumped.value - T);  // into the solid node
  auto r = out.residual();
  auto K = out.tangent();
  r[0] -= heat;
  K(0, 0) += conductance_ * slope;
  for (int k = 0; k < lumped.count; ++k) K(0, 1 + k) -= conductance_ * lumped.grad[k];
  if (lumpedRow_ < 0) {
    flows.boundaryHeat += heat;
    flows.boundaryEntropy += heat / lumped.value;
    return;
  }
  r[lumpedRow_] += heat;
  K(lumpedRow_, 0) -= conductance_ * slope;
  for (int k = 0; k < lumped.count; ++k) K(lumpedRow_, 1 + k) += conductance_ * lumped.grad[k];
}

void SurfaceHeatLink::eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const {
  const TemperatureJet T = thermalVariable_.step(args.zOld[dofs()[0]], args.zNew[dofs()[0]]);
  exchange(T.value, T.slope, ws, out, flows);
}

void SurfaceHeatLink::rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const {
  const TemperatureJet T = thermalVariable_.rate(args.z[dofs()[0]], args.alpha);
  exchange(T.value, T.slope, ws, out, flows);
}

void SurfaceHeatLink::stageLocal(const StageArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const {
  const TemperatureJet T = thermalVariable_.stage(args, dofs()[0]).temperature;
  exchange(T.value, T.slope, ws, out, flows);
}

}  // namespace mpx
