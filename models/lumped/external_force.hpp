#pragma once
// A time-dependent force F0 f(t) on a mass point. Its work is not part of the energy: it is
// accounted for in the external-work flow (EEM: exactly F(t_mid) . (x' - x)).
#include "engine/core/component.hpp"
#include "engine/core/time_function.hpp"

namespace mpx {

class ExternalForce final : public Component {
 public:
  ExternalForce(std::string name, int positionDof, int velocityDof, const Vec3& force, TimeFunction profile);

  // a force of time alone: no tangent
  bool couples(int, int, LocalForm) const override { return false; }
  void measure(const double* z, Measures& out) const override;
  void eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  void rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  // eem4: no energy: its power is external work at each stage
  StageForm stageForm() const override { return StageForm::RateAtStages; }

 private:
  // Residual -F(t) on the momentum rows and the power F(t) . velocity.
  void apply(double t, const Vec3& velocity, LocalSystem& out, Flows& flows) const;

  int positionDof_, velocityDof_;
  Vec3 force_;
  TimeFunction profile_;
};

}  // namespace mpx
