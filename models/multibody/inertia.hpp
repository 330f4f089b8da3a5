#pragma once
// A constant diagonal mass matrix over consecutive blocks of three position dofs, with the
// velocity dofs of the blocks at the same offsets. A point mass is one translational block; a
// rigid body (centre of mass and three directors, docs/theory.md section 7) is a translational
// block of mass m and three director blocks of "masses" E_i = (J_j + J_k - J_i)/2. Rows:
// kinematics x' = v, momentum m v' = m g (gravity on translational blocks; its potential
// -m g.x is part of the energy).
#include "engine/core/component.hpp"

namespace mpx {

struct InertiaBlock {
  double mass;
  bool translational;  // feels gravity and carries linear momentum (directors do not)
};

class Inertia final : public Component {
 public:
  Inertia(std::string name, int firstPositionDof, int firstVelocityDof, std::vector<InertiaBlock> blocks,
          const Vec3& gravity);

  // kinematic rows: the dof's own position and velocity; momentum rows: its own velocity
  bool couples(int row, int column, LocalForm) const override {
    const int velocityRows = 3 * static_cast<int>(blocks_.size());
    return column == row || (row < velocityRows && column == row + velocityRows);
  }
  void measure(const double* z, Measures& out) const override;
  // translational blocks are points, director blocks directions
  void spatialVectors(std::vector<SpatialVector>& out) const override;
  void eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  void rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  // eem4: a kinetic energy quadratic in the velocities and a constant weight
  StageForm stageForm() const override { return StageForm::RateAtStages; }

 private:
  // Gravity force on block b.
  Vec3 weight(std::size_t b) const {
    return blocks_[b].translational ? Vec3(blocks_[b].mass * gravity_) : Vec3::Zero();
  }

  int firstPositionDof_, firstVelocityDof_;
  std::vector<InertiaBlock> blocks_;
  Vec3 gravity_;
};

}  // namespace mpx
