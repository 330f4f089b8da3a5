#pragma once
// A prescribed force F0 f(t) along the current line between two end points, pushing them apart
// for F0 f(t) > 0: equal and opposite at the two ends and along their separation, so it keeps
// linear and angular momentum. Its work is not part of the energy: it is the external-work
// flow, in an EEM step exactly F(t_mid) (lambda' - lambda) with the force along the discrete
// gradient 2 d_mid / (lambda + lambda') of the length lambda.
#include "engine/core/time_function.hpp"
#include "models/lumped/two_point_geometry.hpp"

namespace mpx {

class Actuator final : public Component {
 public:
  Actuator(std::string name, const Endpoint& a, const Endpoint& b, double force, TimeFunction profile);

  // writes momentum rows only, through the separation
  bool couples(int row, int column, LocalForm) const override { return geometry_.couples(row, column, false); }
  void measure(const double* z, Measures& out) const override;
  void eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  void rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  // eem4: no energy: its power is external work at each stage
  StageForm stageForm() const override { return StageForm::RateAtStages; }

 private:
  TwoPointGeometry geometry_;
  double force_;
  TimeFunction profile_;
};

}  // namespace mpx
