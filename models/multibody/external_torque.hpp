#pragma once
// A time-dependent torque tau(t) = tau0 f(t) on a rigid body (centre of mass + directors). It
// acts as the director forces f_i = tau x d_i / 2, whose virtual work sum f_i . (dtheta x d_i)
// equals tau . dtheta for orthonormal directors. In an EEM step the forces use the mid-step
// directors, so the work accounted for is exactly sum f_i . (d_i' - d_i) (external work flow).
#include "engine/core/component.hpp"
#include "engine/core/time_function.hpp"

namespace mpx {

class ExternalTorque final : public Component {
 public:
  // firstDirectorDof: global dof of d1 (d2, d3 follow); velocityShift: velocity dof - position dof.
  ExternalTorque(std::string name, int firstDirectorDof, int velocityShift, const Vec3& torque, TimeFunction profile);

  // local order: 9 director positions, their 9 velocity rows; writes director i's velocity rows
  // against its own positions, through tau x d_i (no entry on the cross product's diagonal)
  bool couples(int row, int column, LocalForm) const override {
    return row >= 9 && column < 9 && (row - 9) / 3 == column / 3 && row % 3 != column % 3;
  }
  void measure(const double* z, Measures& out) const override;
  void eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  void rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  // eem4: no energy: its power is external work at each stage
  StageForm stageForm() const override { return StageForm::RateAtStages; }

 private:
  // Residual -tau x d_i / 2 on the director momentum rows, the power with the director rates,
  // and the tangent coefficient of d(residual)/d(d_i) (0.25 for mid-step directors in EEM).
  void apply(double t, const double* directorsForce, const double* directorRates, double tangentCoefficient,
             LocalSystem& out, Flows& flows) const;

  int firstDirectorDof_, velocityShift_;
  Vec3 torque_;
  TimeFunction profile_;
};

}  // namespace mpx
