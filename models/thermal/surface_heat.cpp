#include "models/thermal/surface_heat.hpp"

namespace mpx {

SurfaceHeat::SurfaceHeat(SurfaceHeatSpec spec) : Component(spec.name, {spec.thermalDof}), spec_(std::move(spec)) {}

void SurfaceHeat::exchange(double T, double slope, double q, LocalSystem& out, Flows& flows) const {
  const double fluxHeat = spec_.area * q,
               convectionHeat = spec_.area * spec_.convection * (spec_.ambientTemperature - T);
  out.r[0] -= fluxHeat + convectionHeat;
  out.k[0] += spec_.area * spec_.convection * slope;
  flows.boundaryHeat += fluxHeat + convectionHeat;
  flows.boundaryEntropy += fluxHeat / T + convectionHeat / spec_.ambientTemperature;
}

// the flux at the step's midpoint time, which the residual stands for
void SurfaceHeat::eemLocal(const StepArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  const TemperatureJet T = spec_.thermalVariable.step(args.zOld[spec_.thermalDof], args.zNew[spec_.thermalDof]);
  exchange(T.value, T.slope, spec_.flux * spec_.profile(args.t + 0.5 * args.dt), out, flows);
}

void SurfaceHeat::rateLocal(const RateArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  const TemperatureJet T = spec_.thermalVariable.rate(args.z[spec_.thermalDof], args.alpha);
  exchange(T.value, T.slope, spec_.flux * spec_.profile(args.t), out, flows);
}

void SurfaceHeat::stageLocal(const StageArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  const TemperatureJet T = spec_.thermalVariable.stage(args, spec_.thermalDof).temperature;
  exchange(T.value, T.slope, spec_.flux * spec_.profile(args.t + args.rule->node[args.stage] * args.dt), out, flows);
}

}  // namespace mpx
