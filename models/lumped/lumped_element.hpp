#pragma once
// A lumped thermo-mechanical element: energy e(c, s, gamma) and entropy eta(c, s, gamma) of a
// stretch invariant c = |x_b - x_a|^2 between two end points, an own thermal node s and an
// internal (viscous) variable gamma, each optional. Thermo-springs, Maxwell elements (with or
// without a thermal node), elastic springs and heat reservoirs are all this component with a
// different law; one recipe (docs/theory.md section 4) serves both thermal variables:
//   theta~ = D_s e / D_s eta,  f~ = D_c e - theta~ D_c eta,  g~ = -(D_gamma e - theta~ D_gamma eta)
//   momentum:  f~ dc/dq(q_mid)          internal: nu (gamma' - gamma)/dt = g~
//   thermal:   theta~ (eta' - eta)/dt = g~^2/nu + heat from links
// with D the discrete gradient in an EEM step, the exact partials in the rate form and the
// energy-consistent stage gradient in an eem4 step.
#include "engine/core/stage_gradient.hpp"
#include "models/lumped/element_laws.hpp"
#include "models/lumped/two_point_geometry.hpp"

#include <memory>
#include <optional>

namespace mpx {

enum class DiscreteGradientForm { Partitioned, Gonzalez };

// nu(theta) = nuRef exp(-activation (theta - thetaRef)); constant without a thermal node.
struct Viscosity {
  double reference = 1.0;
  double activation = 0.0;
  double referenceTemperature = 1.0;
};

struct LumpedElementSpec {
  std::string name;
  std::optional<std::pair<Endpoint, Endpoint>> ends;  // absent: no stretch (a reservoir)
  std::shared_ptr<const ElementLaw> law;
  int thermalDof = -1;   // global dof of s, -1: isothermal
  int thermalNode = -1;  // node index published for heat links
  int internalDof = -1;  // global dof of gamma, -1: no internal variable
  Viscosity viscosity;
  Vec3 argumentScale = Vec3::Ones();  // characteristic magnitudes of (c, s, gamma)
  DiscreteGradientForm form = DiscreteGradientForm::Partitioned;
};

class LumpedElement final : public Component {
 public:
  explicit LumpedElement(LumpedElementSpec spec);

  // writes momentum, thermal and internal rows, never the end points' kinematic rows, and reads
  // the separation's rate from the position rates, never the velocities
  bool couples(int row, int column, LocalForm) const override {
    return !geometry_ || geometry_->couples(row, column, false);
  }
  void measure(const double* z, Measures& out) const override;
  void eemLocal(const StepArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  void rateLocal(const RateArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  StageForm stageForm() const override { return StageForm::Own; }
  void stageLocal(const StageArgs& args, Workspace& ws, LocalSystem& out, Flows& flows) const override;
  std::unique_ptr<StageScratch> makeStageScratch() const override { return std::make_unique<StageData>(); }

 private:
  // Conjugate quantities and their derivatives over the local dofs.
  struct Response {
    double force = 0.0, theta = 0.0, drivingForce = 0.0, viscosity = 1.0;
    LocalRow dForce, dTheta, dDrivingForce, dViscosity;
  };
  static std::vector<int> collectDofs(const LumpedElementSpec& spec);
  // The separation d of the two ends (zero without ends), and the arguments (c = |d|^2, s, gamma).
  Vec3 separation(const double* z) const;
  Vec3 arguments(const double* z, const Vec3& separation) const;
  // From the (discrete) gradients of energy and entropy over (c, s, gamma).
  Response respond(const GradientRows& dEnergy, const GradientRows& dEntropy) const;
  // Rows over local dofs of d(c, s, gamma)/dz, c's at separation d; empty without a tangent,
  // so that a residual-only evaluation carries no derivatives (respond, addBalances).
  void argumentRows(const Vec3& separation, LocalRow (&rows)[3], bool tangent) const;
  static LocalRow chain(const Vec3& dArguments, const LocalRow (&rows)[3]);
  // A discrete gradient's derivative with respect to b, carried onto the local dofs.
  static GradientRows alongRows(const DiscreteGradient& gradient, const LocalRow (&rows)[3]);
  // What an eem4 evaluation's passes share: the arguments along the stage polynomial (the
  // rows for the tangent's column are rewritten at each call), the separations and their rates
  // at the stages, and the law's jets along the path (the entropy's only at the end when it is
  // linear).
  struct StageData final : StageScratch {
    StagePath path;
    Vec3 separation[CollocationRule::kMostStages], separationRate[CollocationRule::kMostStages];
    StageJets energy, entropy;
  };
  // Fill what does not depend on the stage or the tangent's column.
  void fillStageData(const StageArgs& args, StageData& data) const;
  // The rows of the tangent's column args.column: da'_j/dZ_column.
  void columnRows(const StageArgs& args, StageData& data) const;
  // stageLocal from the evaluation's stage data.
  void stageBalances(const StageArgs& args, StageData& data, Workspace& ws, LocalSystem& out, Flows& flows) const;
  // Residual rows shared by all forms and the tangent terms through the response's
  // derivatives (times zCoefficient): momentum f (2 d), internal nu gammaRate - g, thermal
  // theta entropyRate - g^2/nu; also publishes the node temperature.
  void addBalances(const Response& response, double zCoefficient, const Vec3& forceDirection, double gammaRate,
                   double entropyRate, Workspace& ws, LocalSystem& out, Flows& flows) const;

  LumpedElementSpec spec_;
  std::optional<TwoPointGeometry> geometry_;
  unsigned mask_ = 0;
  int localThermal_ = -1, localInternal_ = -1;
  bool linearEntropy_ = false;  // the law's entropy is linear: its discrete gradients are exact
};

}  // namespace mpx
