#include "models/thermal/surface_heat.hpp"

#include "engine/core/discrete_gradient.hpp"

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
  const LogarithmicMean mean = logarithmicMean(args.zOld[spec_.thermalDof], args.zNew[spec_.thermalDof]);
  exchange(mean.value, mean.derivative, spec_.flux * spec_.profile(args.t + 0.5 * args.dt), out, flows);
}

void SurfaceHeat::rateLocal(const RateArgs& args, Workspace&, LocalSystem& out, Flows& flows) const {
  exchange(args.z[spec_.thermalDof], args.alpha, spec_.flux * spec_.profile(args.t), out, flows);
}

}  // namespace mpx
