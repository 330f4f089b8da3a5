#pragma once
// A heat reservoir at a prescribed temperature (Dirichlet): a thermal node without a dof whose
// temperature heat links read. Its energy is outside the system; heat through it is the
// boundary-heat flow (accounted for by the links).
#include "engine/core/component.hpp"

namespace mpx {

class FixedTemperature final : public Component {
 public:
  FixedTemperature(std::string name, int node, double temperature);

  void measure(const double* z, Measures& out) const override;
  void eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  void rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  // eem4: no energy: a temperature published at each stage
  StageForm stageForm() const override { return StageForm::RateAtStages; }

 private:
  void publish(Workspace& ws) const;
  int node_;
  double temperature_;
};

}  // namespace mpx
