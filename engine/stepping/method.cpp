#include "engine/stepping/method.hpp"

#include "engine/core/input_error.hpp"

namespace mpx {

std::optional<Method> methodByName(const std::string& name) {
  if (name == "eem") return Method{name, Scheme::Eem, std::nullopt};
  if (name == "eem-entropy") return Method{name, Scheme::Eem, ThermalVariable::Entropy};
  if (name == "eem-temperature") return Method{name, Scheme::Eem, ThermalVariable::Temperature};
  if (name == "midpoint") return Method{name, Scheme::Midpoint, std::nullopt};
  if (name == "trapezoidal") return Method{name, Scheme::Trapezoidal, std::nullopt};
  if (name == "ida") return Method{name, std::nullopt, std::nullopt};
  return std::nullopt;
}

void checkMethodSupports(const Method& method, const Model& model, const std::string& scene) {
  if (!method.isIda()) return;
  for (const PrescribedMotion& motion : model.prescribedMotions())
    if (motion.displacement)
      throw InputError(scene +
                       ": integrator 'ida' cannot impose a <prescribed_displacement>: give the motion as a "
                       "<prescribed_velocity>, or use a one-step integrator");
}

RunSummary runMethod(const Model& model, const Method& method, const MethodParameters& p, const StepSink& sink,
                     const ProgressSink& progress) {
  if (method.isIda())
    return simulateIda(model, {p.relativeTolerance, p.absoluteTolerance, p.maxOrder, p.dt, p.tEnd}, sink, progress);
  const RunOptions options{*method.scheme, p.dt, p.tEnd, p.newton};
  if (p.adaptive)
    return simulateAdaptive(model, options, {p.relativeTolerance, p.absoluteTolerance, p.outputInterval}, sink,
                            progress);
  return simulate(model, options, sink, progress);
}

}  // namespace mpx
