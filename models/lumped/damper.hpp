#pragma once
// Isothermal Kelvin-Voigt dashpot between two end points: force coefficient * rate of the
// length lambda = |x_b - x_a|, opposing it. It stores no energy; its power goes to the
// dissipated-energy flow. In an EEM step the force is coefficient (lambda' - lambda)/dt along
// the discrete gradient of lambda, 2 d_mid / (lambda + lambda'), so the dissipated energy is
// exactly coefficient (lambda' - lambda)^2 / dt.
#include "models/lumped/two_point_geometry.hpp"

namespace mpx {

class Damper final : public Component {
 public:
  Damper(std::string name, const Endpoint& a, const Endpoint& b, double coefficient);

  // writes momentum rows only; the step's length rate is the positions' (lambda' - lambda)/dt, the
  // rate form's reads the velocities
  bool couples(int row, int column, LocalForm form) const override {
    return geometry_.couples(row, column, form != LocalForm::Step);
  }
  void measure(const double* z, Measures& out) const override;
  void eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  void rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  // eem4: no energy: its power is dissipated at each stage
  StageForm stageForm() const override { return StageForm::RateAtStages; }

 private:
  TwoPointGeometry geometry_;
  double coefficient_;
};

}  // namespace mpx
