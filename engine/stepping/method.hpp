#pragma once
// Integration methods by name, and one entry point that runs any of them on a model:
// EEM (with the scene's or a forced thermal variable), fourth-order EEM (eem4), implicit
// midpoint, trapezoidal, IDA.
#include "engine/core/model.hpp"
#include "engine/stepping/adaptive_simulation.hpp"
#include "engine/stepping/ida_simulation.hpp"
#include "engine/stepping/simulation.hpp"

#include <optional>
#include <string>

namespace mpx {

struct Method {
  std::string name;
  std::optional<Scheme> scheme;                    // the one-step scheme; none for SUNDIALS IDA
  std::optional<ThermalVariable> thermalVariable;  // forced by the method (eem-entropy, ...)
  bool adaptive = false;                           // a one-step scheme with adaptive steps
  int maxOrder = 0;  // IDA: the largest BDF order the method allows (ida-bdfK); 0: the run's
  bool isIda() const { return !scheme; }
  // Set by a tolerance rather than a step: IDA and the adaptive one-step schemes.
  bool takesTolerance() const { return isIda() || adaptive; }
};

// The names methodByName accepts, for messages; each one-step name also takes the suffix
// "-adaptive" (eem-adaptive, eem4-adaptive, ...), and ida-bdfK is IDA up to BDF order K, so that
// one bench run can hold IDA at the order that suits a scene next to IDA at its default 5.
inline constexpr const char* kMethodNames =
    "eem, eem-entropy, eem-temperature, midpoint, trapezoidal, eem4 (each also as NAME-adaptive), ida, ida-bdfK "
    "(BDF order at most K = 1-5)";
std::optional<Method> methodByName(const std::string& name);

struct MethodParameters {
  double dt = 0.0;  // step of one-step schemes (adaptive: the first); IDA's output interval
  double tEnd = 0.0;
  NewtonSettings newton;
  bool adaptive = false;            // one-step schemes: adaptive steps
  double relativeTolerance = 1e-6;  // IDA and adaptive steps
  double absoluteTolerance = 1e-6;  // IDA and adaptive steps, times each dof's scale
  double outputInterval = 0.0;      // adaptive steps land on its multiples
  int maxOrder = 5;                 // IDA, unless the method sets its own
  bool sundialsKlu = false;         // IDA: SUNDIALS' KLU rather than Metriplex's sparse LU
  Checkpointing checkpoints;        // one-step schemes only (IDA's multistep history cannot be saved)
  bool componentFlows = false;      // one-step schemes: StepRecord::componentCrossed
};

// Throw InputError if `method` cannot integrate `model`: eem4 needs every component to have a
// stage form; IDA needs every prescribed motion as a velocity (a displacement is imposed step by
// step through the mean velocity, which a rate form cannot express).
// `scene` names the scene file in the message.
void checkMethodSupports(const Method& method, const Model& model, const std::string& scene);

// Fixed-step runs take at most this many steps (a step count must fit the step counters).
inline constexpr double kMostSteps = 1e9;
// Below this relative tolerance the round-off of a state exceeds what it asks of a step.
inline constexpr double kSmallestRelativeTolerance = 1e-14;
// Throw InputError, prefixed by `where`, if t_end / dt asks for more than kMostSteps steps.
void checkStepCount(double tEnd, double dt, const std::string& where);

RunSummary runMethod(const Model& model, const Method& method, const MethodParameters& parameters, const StepSink& sink,
                     const ProgressSink& progress = nullptr);

}  // namespace mpx
