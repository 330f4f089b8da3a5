#include "method.hpp"

namespace mpx {

std::optional<Method> methodByName(const std::string& name) {
  if (name == "eem") return Method{name, false, Scheme::Eem, std::nullopt};
  if (name == "eem-entropy") return Method{name, false, Scheme::Eem, ThermalVariable::Entropy};
  if (name == "eem-temperature") return Method{name, false, Scheme::Eem, ThermalVariable::Temperature};
  if (name == "midpoint") return Method{name, false, Scheme::Midpoint, std::nullopt};
  if (name == "trapezoidal") return Method{name, false, Scheme::Trapezoidal, std::nullopt};
  if (name == "ida") return Method{name, true, Scheme::Eem, std::nullopt};
  return std::nullopt;
}

RunSummary runMethod(const Model& model, const Method& method, const MethodParameters& p, const StepSink& sink,
                     const ProgressSink& progress) {
  if (method.ida)
    return simulateIda(model, {p.relativeTolerance, p.absoluteTolerance, p.maxOrder, p.dt, p.tEnd}, sink, progress);
  return simulate(model, {method.scheme, p.dt, p.tEnd, p.newton}, sink, progress);
}

}  // namespace mpx
