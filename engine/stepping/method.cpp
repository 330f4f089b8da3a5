#include "engine/stepping/method.hpp"

#include "engine/core/input_error.hpp"

#include <cstdio>

namespace mpx {

namespace {

std::optional<Method> fixedStepMethod(const std::string& name) {
  if (name == "eem") return Method{name, Scheme::Eem, std::nullopt};
  if (name == "eem-entropy") return Method{name, Scheme::Eem, ThermalVariable::Entropy};
  if (name == "eem-temperature") return Method{name, Scheme::Eem, ThermalVariable::Temperature};
  if (name == "eem4") return Method{name, Scheme::Eem4, std::nullopt};
  if (name == "midpoint") return Method{name, Scheme::Midpoint, std::nullopt};
  if (name == "trapezoidal") return Method{name, Scheme::Trapezoidal, std::nullopt};
  return std::nullopt;
}

}  // namespace

std::optional<Method> methodByName(const std::string& name) {
  if (name == "ida") return Method{name, std::nullopt, std::nullopt};
  if (name.size() == 8 && name.compare(0, 7, "ida-bdf") == 0 && name[7] >= '1' && name[7] <= '5') {
    Method ida{name, std::nullopt, std::nullopt};
    ida.maxOrder = name[7] - '0';
    return ida;
  }
  const std::string suffix = "-adaptive";
  const bool adaptive =
      name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
  std::optional<Method> method = fixedStepMethod(adaptive ? name.substr(0, name.size() - suffix.size()) : name);
  if (method) method->name = name, method->adaptive = adaptive;
  return method;
}

void checkMethodSupports(const Method& method, const Model& model, const std::string& scene) {
  if (method.scheme == Scheme::Eem4)
    for (const auto& component : model.components())
      if (component->stageForm() == Component::StageForm::None)
        throw InputError(scene + ": integrator '" + method.name + "' has no fourth-order form for element '" +
                         component->name() + "' (docs/theory.md section 13)");
  if (!method.isIda()) return;
  for (const PrescribedMotion& motion : model.prescribedMotions())
    if (motion.kind == PrescribedKind::Displacement)
      throw InputError(motion.declaredAt +
                       ": integrator 'ida' cannot impose a prescribed displacement: give the motion as a "
                       "<prescribed_velocity>, or use a one-step integrator");
}

void checkStepCount(double tEnd, double dt, const std::string& where) {
  if (!(tEnd / dt <= kMostSteps)) {
    char count[32];
    std::snprintf(count, sizeof count, "%.3g", tEnd / dt);
    throw InputError(where + ": t_end / dt = " + count + " steps; at most 1e9 are taken");
  }
}

RunSummary runMethod(const Model& model, const Method& method, const MethodParameters& p, const StepSink& sink,
                     const ProgressSink& progress) {
  if (method.isIda())
    return simulateIda(model,
                       {p.relativeTolerance, p.absoluteTolerance, method.maxOrder > 0 ? method.maxOrder : p.maxOrder,
                        p.sundialsKlu, p.newton.corotate, p.dt, p.tEnd},
                       sink, progress);
  const RunOptions options{*method.scheme, p.dt, p.tEnd, p.newton, p.checkpoints, p.componentFlows};
  if (p.adaptive || method.adaptive)
    return simulateAdaptive(model, options, {p.relativeTolerance, p.absoluteTolerance, p.outputInterval}, sink,
                            progress);
  return simulate(model, options, sink, progress);
}

}  // namespace mpx
