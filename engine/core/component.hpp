#pragma once
// The one interface every physical effect implements. A component touches a fixed list of
// state dofs (its local dofs); the engine evaluates it on preallocated local buffers and
// scatters the result. Energy, entropy and momenta of the system are plain sums over components.
#include "engine/core/collocation_rule.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace mpx {

using Vec3 = Eigen::Vector3d;

// Largest number of local dofs of one component: a thermo-viscoelastic 8-node hexahedron
// touches 24 positions, their 24 velocity rows, 6 internal variables at each of 8 quadrature
// points and 8 temperatures.
inline constexpr int kMaxLocalDofs = 104;

// Temperature of a thermal node as seen by the heat links that touch it: the discrete
// temperature theta~ in an EEM step, theta(z) in a rate evaluation. The owner publishes it
// together with its derivative with respect to the owner's local dofs, already multiplied
// by the coefficient the tangent applies to z-derivatives (1 in EEM, alpha in rate form).
struct NodeTemperature {
  double value = 0.0;
  int count = 0;  // number of owner-local dofs in grad (0 for a prescribed temperature)
  double grad[kMaxLocalDofs] = {};
};

// What a component's stage form computes once per eem4 evaluation and takes up again in the
// evaluation's later passes (StageArgs::samePath): the path of its arguments, its law's jets.
struct StageScratch {
  virtual ~StageScratch() = default;
};

// Scratch shared by the components of one evaluation, allocated once per model.
struct Workspace {
  std::vector<NodeTemperature> nodes;
  // per component, in the model's order; null where a component keeps none
  std::vector<std::unique_ptr<StageScratch>> stageScratch;
};

// One EEM step from zOld at time t to zNew at time t + dt. Without `tangent` only the residual
// is wanted (Newton iterations that keep a factorisation): a component may skip the tangent.
struct StepArgs {
  const double* zOld;
  const double* zNew;
  double t;
  double dt;
  bool tangent = true;
};

// A rate evaluation F(t, z, zdot); the tangent wanted is alpha dF/dz + beta dF/dzdot (none when
// both are 0: a component may then skip computing it).
struct RateArgs {
  const double* z;
  const double* zdot;
  double t;
  double alpha;
  double beta;
};

// One stage of a Gauss collocation step (eem4) from zOld at t over dt: the state's polynomial
// passes through zOld and the stage values; stageState[l] and stageRate[l] are z and z' at
// t + c_l dt, zEnd is z(t + dt). Wanted: the residual of stage `stage` and its derivative with
// respect to the values of stage `column`; without `tangent`, the residual alone (column =
// stage), and a component may skip the tangent. With `samePath` the component was called at
// the same stage values before in this evaluation (a later pass over the stages and columns):
// what depends on neither `stage` nor `column` may be taken from its stage scratch.
struct StageArgs {
  const CollocationRule* rule;
  const double* zOld;
  const double* zEnd;
  const double* const* stageState;
  const double* const* stageRate;
  double t;
  double dt;
  int stage;
  int column;
  bool tangent = true;
  bool samePath = false;
  // The rate form at this stage, with the coefficients of the tangent for stage `column` (none
  // without `tangent`).
  RateArgs rateArgs() const {
    const double alpha = tangent && stage == column ? 1.0 : 0.0;
    return {stageState[stage], stageRate[stage], t + rule->node[stage] * dt, alpha,
            tangent ? rule->rate[stage][column + 1] / dt : 0.0};
  }
};

// Power crossing the system boundary or leaving the mechanical energy (W): viscous power
// without a thermal node, power of time-dependent external loads, heat through prescribed
// temperatures and thermal boundaries into the system; and the entropy that heat brings in
// (W/K: heat over the temperature at which it crosses).
// The same, integrated over a step or a run, is the energy (J) and entropy (J/K) that crossed.
struct Flows {
  double dissipated = 0.0;
  double externalWork = 0.0;
  double boundaryHeat = 0.0;
  double boundaryEntropy = 0.0;

  Flows& operator+=(const Flows& other) {
    dissipated += other.dissipated;
    externalWork += other.externalWork;
    boundaryHeat += other.boundaryHeat;
    boundaryEntropy += other.boundaryEntropy;
    return *this;
  }
  Flows operator*(double factor) const {
    return {factor * dissipated, factor * externalWork, factor * boundaryHeat, factor * boundaryEntropy};
  }
};

// Local residual r (n) and tangent K (n x n, column-major), zeroed before each evaluation.
struct LocalSystem {
  int n = 0;
  double* r = nullptr;
  double* k = nullptr;
  Eigen::Map<Eigen::VectorXd> residual() { return {r, n}; }
  Eigen::Map<Eigen::MatrixXd> tangent() { return {k, n, n}; }
};

// A row vector over the local dofs of one component (fixed capacity: no heap).
using LocalRow = Eigen::Matrix<double, 1, Eigen::Dynamic, Eigen::RowMajor, 1, kMaxLocalDofs>;

// What the history reports about one state.
struct Measures {
  double energy = 0.0;
  double entropy = 0.0;
  Vec3 momentum = Vec3::Zero();
  Vec3 angularMomentum = Vec3::Zero();
  double constraintViolation = 0.0;
  std::vector<double> nodeTemperature;  // one entry per thermal node
};

// Every measure the history writes is finite.
inline bool finite(const Measures& m) {
  return std::isfinite(m.energy) && std::isfinite(m.entropy) && std::isfinite(m.constraintViolation) &&
         m.momentum.allFinite() && m.angularMomentum.allFinite() &&
         std::all_of(m.nodeTemperature.begin(), m.nodeTemperature.end(), [](double t) { return std::isfinite(t); });
}

class Component {
 public:
  virtual ~Component() = default;

  // Global state indices of the local dofs, in local order.
  const std::vector<int>& dofs() const { return dofs_; }
  // Name used in messages and output.
  const std::string& name() const { return name_; }
  // Coupling components (heat links) read node temperatures published by the others, so
  // they are evaluated after all non-coupling components.
  virtual bool isCoupling() const { return false; }
  // Whether local residual row `row` may depend on local dof `column` in the local form the
  // engine assembles (eemLocal, rateLocal or, for eem4, stageLocal and rateLocal at the
  // stages). The tangent's sparsity pattern holds only such pairs; entries a component
  // writes elsewhere are dropped. A component that takes its rate form at the stages
  // (RateAtStages) must answer for Stages as for Rate.
  enum class LocalForm { Step, Rate, Stages };
  virtual bool couples(int /*row*/, int /*column*/, LocalForm /*form*/) const { return true; }

  // Add energy, entropy, momenta and node temperatures of state z.
  virtual void measure(const double* z, Measures& out) const = 0;
  // The spatial 3-vectors among the dofs a component owns: the global index of the first of
  // three consecutive entries, and of the vector paired with it (a position's velocity, a
  // constraint multiplier's GGL multiplier mu). Points and directions (directors) of the
  // configuration fix the rotation a kept factorisation is turned by; forces (multipliers) are
  // only turned with it (engine/linear/corotation.hpp).
  struct SpatialVector {
    enum class Kind { Point, Direction, Force };
    int first, paired;
    Kind kind;
  };
  virtual void spatialVectors(std::vector<SpatialVector>& /*out*/) const {}
  // EEM step residual (rate form, ~ F(t + dt/2, z_mid, (zNew - zOld)/dt)) and its derivative
  // with respect to zNew.
  virtual void eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const = 0;
  // Continuous residual F(t, z, zdot) and alpha dF/dz + beta dF/dzdot.
  virtual void rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const = 0;

  // How the component enters an eem4 step. Its rate form at each stage keeps the balances when
  // its energy is quadratic in the state or absent (RateAtStages); a non-quadratic energy needs
  // an energy-consistent form of its own (Own: stageLocal). None: eem4 refuses the scene.
  enum class StageForm { None, RateAtStages, Own };
  virtual StageForm stageForm() const { return StageForm::None; }
  virtual void stageLocal(const StageArgs& /*args*/, Workspace& /*ws*/, LocalSystem& /*out*/, Flows& /*flows*/) const {}
  // The stage scratch a model's workspace holds for this component (none by default).
  virtual std::unique_ptr<StageScratch> makeStageScratch() const { return nullptr; }
  // A residual-only eem4 evaluation: a component whose stages share work (a solid cell: each
  // point's path through all stages) gives every stage's residual at once, out[l] and flows[l]
  // for stage l, in place of one stageLocal per stage. Such a component neither publishes nor
  // reads node temperatures, which the stages' evaluations exchange one stage at a time.
  virtual bool evaluatesStagesTogether() const { return false; }
  virtual void stageResiduals(const StageArgs& /*args*/, Workspace& /*ws*/, LocalSystem* /*out*/,
                              Flows* /*flows*/) const {}

 protected:
  Component(std::string name, std::vector<int> dofs) : name_(std::move(name)), dofs_(std::move(dofs)) {}
  // This component's stage scratch in `ws` (made by makeStageScratch), or null: outside a
  // model's workspace, or for a component that keeps none.
  StageScratch* stageScratch(Workspace& ws) const {
    return modelIndex_ >= 0 && modelIndex_ < static_cast<int>(ws.stageScratch.size())
               ? ws.stageScratch[modelIndex_].get()
               : nullptr;
  }

 private:
  friend class Model;
  std::string name_;
  std::vector<int> dofs_;
  int modelIndex_ = -1;  // position in the model's components, set by the model
};

}  // namespace mpx
