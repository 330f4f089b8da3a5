#pragma once
// Global residual and sparse tangent with a pattern fixed at construction. Each component's
// local system is scattered through a precomputed map into the compressed matrix values, so
// assembly allocates nothing and never rebuilds the pattern.
#include "engine/core/component.hpp"
#include "engine/core/model.hpp"

#include <Eigen/Sparse>

#include <vector>

namespace mpx {

class Assembler {
 public:
  explicit Assembler(const Model& model);

  // Zero residual, tangent values and the flows of the evaluation.
  void clear();
  // Add every component's EEM step residual and tangent.
  void addStep(const Model& model, Workspace& ws, const StepArgs& args) {
    add(model, ws, 1.0, [&](const Component& c, Workspace& w, LocalSystem& l, Flows& f) { c.eemLocal(args, w, l, f); });
  }
  // Replace the rows of prescribed motions for the step zOld -> zNew: v' = V(t + dt) (tangent
  // 1/dt) or (v + v')/2 = (u(t + dt) - u(t))/dt (tangent 1/2), with the reaction's work at the
  // mean velocity.
  void imposeStepMotions(const Model& model, const double* zOld, const double* zNew, double t, double dt);
  // The same in rate form, for prescribed velocities: vdot = dV/dt(t), tangent beta.
  void imposeRateMotions(const Model& model, const double* z, const double* zdot, double t, double beta);
  // Add every component's rate residual and tangent times `weight` (trapezoidal rule: two
  // evaluations of weight 1/2).
  void addRate(const Model& model, Workspace& ws, const RateArgs& args, double weight) {
    add(model, ws, weight,
        [&](const Component& c, Workspace& w, LocalSystem& l, Flows& f) { c.rateLocal(args, w, l, f); });
  }

 private:
  // Evaluate every component with evaluate(component, workspace, local, flows) and add the
  // result times `weight`.
  template <class Evaluate>
  void add(const Model& model, Workspace& ws, double weight, const Evaluate& evaluate) {
    const auto& components = model.components();
    for (std::size_t c = 0; c < components.size(); ++c) {
      LocalSystem local{static_cast<int>(components[c]->dofs().size()), localResidual_.data(), localTangent_.data()};
      std::fill_n(local.r, local.n, 0.0);
      std::fill_n(local.k, local.n * local.n, 0.0);
      Flows componentFlows;
      evaluate(*components[c], ws, local, componentFlows);
      scatter(c, components[c]->dofs(), local, weight);
      flows_ += componentFlows * weight;
    }
  }

 public:
  const Eigen::VectorXd& residual() const { return residual_; }
  const Eigen::SparseMatrix<double>& tangent() const { return tangent_; }
  const Flows& flows() const { return flows_; }
  // Row scales sum_j |K_ij| stateScale_j: the change each residual row's terms make over the
  // state's magnitude, so that rows of any unit compare alike.
  void updateRowScale(const Eigen::VectorXd& stateScale);
  // max_i |R_i| / rowScale_i with the last row scales; infinite if R is not finite.
  double relativeResidualNorm() const;

 private:
  // Prescribed motion k: its row becomes `value` with `diagonal` as the only tangent entry;
  // the reaction (the row's residual before) does work at `velocity`.
  void replaceRow(std::size_t k, int dof, double value, double diagonal, double velocity);
  void scatter(std::size_t component, const std::vector<int>& dofs, const LocalSystem& local, double weight);

  Eigen::VectorXd residual_;
  Eigen::VectorXd rowScale_;
  Eigen::SparseMatrix<double> tangent_;
  Flows flows_;
  // per component: (local column-major entry, position in tangent_ values) of its coupled pairs
  std::vector<std::vector<std::pair<int, int>>> scatterMap_;
  std::vector<std::vector<int>> prescribedRowEntries_;  // per prescribed motion: its row in tangent_ values
  std::vector<int> prescribedDiagonal_;
  std::vector<double> localResidual_;
  std::vector<double> localTangent_;
};

}  // namespace mpx
