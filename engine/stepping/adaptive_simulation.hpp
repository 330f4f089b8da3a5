#pragma once
// Adaptive steps for the one-step schemes (EEM, eem4, midpoint, trapezoidal). Each step is an
// ordinary step of the scheme, so every accepted step keeps its balances exactly; what adapts
// is the step size, from an estimate of the step's local error of the scheme's order p
// (C dt^(p+1) |z^(p+1)|, with z^(p+1) from the divided difference of order p + 1 of the
// accepted states, and step doubling where there is no such history yet: at t = 0 and after
// each load breakpoint).
// The error is measured as IDA measures it, in the weighted RMS norm with weights
// 1 / (rtol |z_i| + atol scale_i); a step whose norm exceeds 1 is rejected and retried
// shorter. Steps land on the loads' breakpoints, on multiples of the output interval and on
// t_end.
#include "engine/stepping/simulation.hpp"

namespace mpx {

struct StepControl {
  double relativeTolerance = 1e-6;
  double absoluteTolerance = 1e-6;  // times each dof's scale (Model::dofScale)
  double outputInterval = 0.0;      // steps land on its multiples (0: on t_end only)
};

// Same contract as simulate(), with options.dt the first step tried; one record per accepted
// step, whose dt is the step taken.
RunSummary simulateAdaptive(const Model& model, const RunOptions& options, const StepControl& control,
                            const StepSink& sink, const ProgressSink& progress = nullptr);

}  // namespace mpx
