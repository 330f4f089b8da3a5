#pragma once
// A model compiled once from a scene: dof layout, components (immutable parameters), names,
// initial state. Everything that changes during a run lives in the state vector or in
// workspaces owned by the integrator.
#include "engine/core/component.hpp"
#include "engine/core/layout.hpp"
#include "engine/core/time_function.hpp"

#include <Eigen/Dense>

#include <memory>
#include <string>
#include <vector>

namespace mpx {

// Which thermal variable the Thermal block holds.
enum class ThermalVariable { Temperature, Entropy };

// A dof whose value is prescribed: a clamped or driven node's velocity, whose momentum row is
// replaced by the condition while the reaction force does boundary work, or a temperature
// (Dirichlet), whose heat-balance row is replaced while the reaction is the heat brought in.
// Velocity: v(t) = amplitude * profile(t). Displacement: u(t) = amplitude * profile(t), imposed
// in a step through the mean velocity (v + v')/2 = (u(t + dt) - u(t))/dt, which the kinematic
// row turns into x' - x = u(t + dt) - u(t) exactly. Temperature: theta(t) = amplitude * profile(t).
enum class PrescribedKind { Velocity, Displacement, Temperature };

struct PrescribedMotion {
  int dof;
  double amplitude;
  TimeFunction profile;
  PrescribedKind kind = PrescribedKind::Velocity;
  // the scene element that prescribes it (e.g. "scene.xml:12: <prescribed_displacement>"), for messages
  std::string declaredAt;
};

class Model {
 public:
  Model(Layout layout, ThermalVariable thermalVariable, std::vector<std::unique_ptr<Component>> components,
        std::vector<std::string> thermalNodeNames, Eigen::VectorXd initialState, Eigen::VectorXd dofScale,
        std::vector<PrescribedMotion> prescribedMotions = {}, std::vector<double> loadBreakpoints = {});

  const Layout& layout() const { return layout_; }
  ThermalVariable thermalVariable() const { return thermalVariable_; }
  // Non-coupling components first, then couplings (see Component::isCoupling).
  const std::vector<std::unique_ptr<Component>>& components() const { return components_; }
  const std::vector<std::string>& thermalNodeNames() const { return thermalNodeNames_; }
  const Eigen::VectorXd& initialState() const { return initialState_; }
  // Characteristic magnitude of each dof, used to weigh Newton increments.
  const Eigen::VectorXd& dofScale() const { return dofScale_; }
  const std::vector<PrescribedMotion>& prescribedMotions() const { return prescribedMotions_; }
  // Times where a load or prescribed motion has a kink, increasing and distinct.
  const std::vector<double>& loadBreakpoints() const { return loadBreakpoints_; }
  // The first load breakpoint after t, or infinity: where the time loops land their steps.
  double nextLoadBreakpoint(double t) const;

  // Energy, entropy, momenta and node temperatures of state z; `out` is reused (no allocation
  // once sized).
  void measure(const Eigen::VectorXd& z, Measures& out) const;
  Workspace makeWorkspace() const;

 private:
  Layout layout_;
  ThermalVariable thermalVariable_;
  std::vector<std::unique_ptr<Component>> components_;
  std::vector<std::string> thermalNodeNames_;
  Eigen::VectorXd initialState_;
  Eigen::VectorXd dofScale_;
  std::vector<PrescribedMotion> prescribedMotions_;
  std::vector<double> loadBreakpoints_;
};

}  // namespace mpx
