#pragma once
// A point mass with position and velocity dofs in uniform gravity g (a conservative field:
// its potential -m g.x is part of the energy). Rows: kinematics x' = v, momentum m v' = m g.
#include "engine/component.hpp"

namespace mpx {

class PointMass final : public Component {
 public:
  PointMass(std::string name, double mass, int positionDof, int velocityDof, const Vec3& gravity);

  void measure(const double* z, Measures& out) const override;
  void eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  void rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;

 private:
  double mass_;
  int positionDof_, velocityDof_;
  Vec3 gravity_;
};

}  // namespace mpx
