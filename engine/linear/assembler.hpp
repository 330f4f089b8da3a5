#pragma once
// Global residual and sparse tangent with a pattern fixed at construction. Each component's
// local system is scattered through a precomputed map into the compressed matrix values, so
// assembly allocates nothing and never rebuilds the pattern.
//
// Components are evaluated in batches, in parallel with OpenMP (OMP_NUM_THREADS threads) when
// a batch is large enough to pay for it. The batch's tangents are then scattered in parallel
// too, each thread into its own range of the matrix entries, going through the components in
// order: every entry receives its terms in component order, so the sums, and the results, are
// the same bit for bit for any number of threads.
#include "engine/core/component.hpp"
#include "engine/core/model.hpp"

#include <omp.h>
#include <Eigen/Sparse>

#include <algorithm>
#include <vector>

namespace mpx {

class Assembler {
 public:
  // The pattern is that of the local form `form` the components will be evaluated in.
  // `stages` > 1 (form Stages): the system of an eem4 step, whose unknowns are the values of
  // each stage (stage l's dof i at l n + i) and whose tangent has one block of the model's
  // pattern per pair of stages.
  Assembler(const Model& model, Component::LocalForm form, int stages = 1);
  // The local systems point into the assembler's own buffers.
  Assembler(const Assembler&) = delete;
  Assembler& operator=(const Assembler&) = delete;

  // Zero residual and the flows of the evaluation, and the tangent values if one is to be
  // evaluated (tangent() otherwise keeps the last one evaluated).
  void clear(bool tangent = true);
  // Add every component's EEM step residual and tangent (the residual alone without
  // args.tangent: the tangent then keeps the last one assembled, but for the rows of prescribed
  // motions, which the impose functions rewrite).
  void addStep(const Model& model, Workspace& ws, const StepArgs& args) {
    add(model, ws, {0, 1.0, 1.0, true, args.tangent},
        [&](const Component& c, Workspace& w, LocalSystem& l, Flows& f) { c.eemLocal(args, w, l, f); });
  }
  // Replace the rows of prescribed motions for the step zOld -> zNew: v' = V(t + dt) (tangent
  // 1/dt) or (v + v')/2 = (u(t + dt) - u(t))/dt (tangent 1/2), with the reaction's work at the
  // mean velocity.
  void imposeStepMotions(const Model& model, const double* zOld, const double* zNew, double t, double dt);
  // The same in rate form, for prescribed velocities: vdot = dV/dt(t), tangent beta.
  void imposeRateMotions(const Model& model, const double* z, const double* zdot, double t, double beta);
  // Add every component's rate residual and tangent times `weight` (trapezoidal rule: two
  // evaluations of weight 1/2). With alpha = beta = 0 only the residual is wanted (IDA's
  // residual calls): the tangent is left as it was.
  void addRate(const Model& model, Workspace& ws, const RateArgs& args, double weight) {
    add(model, ws, {0, weight, weight, true, args.alpha != 0.0 || args.beta != 0.0},
        [&](const Component& c, Workspace& w, LocalSystem& l, Flows& f) { c.rateLocal(args, w, l, f); });
  }
  // Add every stage's residual (its flows weighted b_l) and the tangent blocks of all pairs
  // of stages: one evaluation of every component per pair; without args.tangent one per stage,
  // for the residual alone (one for all stages of a component that evaluates them together).
  void addStages(const Model& model, Workspace& ws, StageArgs args);
  // Prescribed motions at every stage: v_l = V'(t_l) or the temperature, tangent 1.
  void imposeStageMotions(const Model& model, const StageArgs& args);

 private:
  // Where one evaluation goes: the tangent block (stage rows, stage columns; 0 for one-stage
  // systems), the weights of its residual and tangent and of its flows, whether the residual
  // and the tangent are wanted.
  struct Pass {
    int block;
    double weight;
    double flowWeight;
    bool withResidual;
    bool withTangent;
  };
  // The components one pass evaluates, in model order: owners first, then couplings, which
  // read the node temperatures their owners publish (so the two never share a batch).
  struct PassOrder {
    std::vector<std::size_t> owners;
    std::vector<std::size_t> couplings;
  };
  // Evaluate the components of `order` with evaluate(component, workspace, local, flows) and
  // add the result as `pass` says.
  template <class Evaluate>
  void add(const Model& model, Workspace& ws, const Pass& pass, const Evaluate& evaluate, const PassOrder& order) {
    addBatches(model, order.owners, ws, pass, evaluate);
    addBatches(model, order.couplings, ws, pass, evaluate);
  }
  template <class Evaluate>
  void add(const Model& model, Workspace& ws, const Pass& pass, const Evaluate& evaluate) {
    add(model, ws, pass, evaluate, everyComponent_);
  }
  template <class Evaluate>
  void addBatches(const Model& model, const std::vector<std::size_t>& indices, Workspace& ws, const Pass& pass,
                  const Evaluate& evaluate) {
    const auto& components = model.components();
    for (std::size_t first = 0; first < indices.size(); first += kBatch) {
      const int count = static_cast<int>(std::min<std::size_t>(kBatch, indices.size() - first));
      const std::size_t* batch = indices.data() + first;
      auto evaluateSlot = [&](int b) {
        LocalSystem& local = locals_[b];
        local.n = static_cast<int>(components[batch[b]]->dofs().size());
        std::fill_n(local.r, local.n, 0.0);
        // a residual-only pass leaves what a component writes into its tangent there, unread
        if (pass.withTangent) std::fill_n(local.k, local.n * local.n, 0.0);
        localFlows_[b] = Flows{};
        evaluate(*components[batch[b]], ws, local, localFlows_[b]);
      };
      forEachSlot(count, evaluateSlot);
      if (pass.withTangent) scatterTangents(batch, count, pass);
      if (!pass.withResidual) continue;
      for (int b = 0; b < count; ++b) {
        scatterResidual(batch[b], components[batch[b]]->dofs(), locals_[b].r, pass.block / stages_, pass.weight);
        flows_ += localFlows_[b] * pass.flowWeight;
        if (keepComponentFlows_) componentFlows_[batch[b]] += localFlows_[b] * pass.flowWeight;
      }
    }
  }

  // evaluate(b) for the slots b < count of a batch, in parallel when that pays
  template <class EvaluateSlot>
  static void forEachSlot(int count, const EvaluateSlot& evaluateSlot) {
    // a small batch, or a single thread, stays outside OpenMP altogether: a region that runs
    // on one thread allocates its team at every entry (libgomp keeps only larger teams)
    if (count >= kSmallestParallelBatch && omp_get_max_threads() > 1) {
#pragma omp parallel for schedule(static)
      for (int b = 0; b < count; ++b) evaluateSlot(b);
    } else {
      for (int b = 0; b < count; ++b) evaluateSlot(b);
    }
  }
  // scatterPart(p) for every part p of the matrix entries, in parallel for a batch of `count` slots
  // where evaluating them would be
  template <class ScatterPart>
  void forEachPart(int count, const ScatterPart& scatterPart) const {
    if (count >= kSmallestParallelBatch && scatterParts_ > 1 && omp_get_max_threads() > 1) {
#pragma omp parallel for schedule(static)
      for (int p = 0; p < scatterParts_; ++p) scatterPart(p);
    } else {
      for (int p = 0; p < scatterParts_; ++p) scatterPart(p);
    }
  }
  // The residuals of all stages of the components that evaluate their stages together.
  void addStagesTogether(const Model& model, Workspace& ws, const StageArgs& args);

 public:
  const Eigen::VectorXd& residual() const { return residual_; }
  const Eigen::SparseMatrix<double>& tangent() const { return tangent_; }
  const Flows& flows() const { return flows_; }
  // The flows of the last evaluation per component, in the model's order, and one more entry:
  // the prescribed motions' reactions; they sum to flows(). Kept only when asked (a budget),
  // so that the step's evaluations do no per-component bookkeeping otherwise.
  void keepComponentFlows(bool keep) { keepComponentFlows_ = keep; }
  const std::vector<Flows>& componentFlows() const { return componentFlows_; }
  // Row scales sum_j |K_ij| stateScale_j: the change each residual row's terms make over the
  // state's magnitude, so that rows of any unit compare alike.
  void updateRowScale(const Eigen::VectorXd& stateScale);
  // max_i |R_i| / rowScale_i with the last row scales; infinite if R is not finite.
  double relativeResidualNorm() const;
  // The first component whose local residual was not finite in an evaluation since
  // forgetNonFinite(), and the state dof of that entry (both -1 if none): what a failure names.
  struct NonFiniteEntry {
    int component = -1;
    int dof = -1;
  };
  const NonFiniteEntry& firstNonFinite() const { return firstNonFinite_; }
  void forgetNonFinite() { firstNonFinite_ = {}; }
  // Write "the residual of <component> at dof <k> (<block>) was not finite ..." into `out` (without
  // allocating: the failure path of a step that a cut-back may still recover); returns the
  // characters written, 0 if no entry was seen.
  int describeNonFinite(const Model& model, char* out, std::size_t size) const;

 private:
  // Prescribed motion k: its row becomes `value` with `diagonal` as the only tangent entry;
  // the reaction (the row's residual before) does work at velocity `conjugate`, or, for a
  // temperature, is heat that enters at temperature `conjugate`.
  // At stage `stage` of a multi-stage system, with the reaction's flows times `weight`.
  void replaceRow(std::size_t k, const PrescribedMotion& p, double value, double diagonal, double conjugate,
                  int stage = 0, double weight = 1.0);
  // Add the tangents of a batch's slots (pass.weight times) to tangent block pass.block: one
  // part of the matrix entries per thread when the batch is large enough.
  void scatterTangents(const std::size_t* batch, int count, const Pass& pass);
  // Add weight r (the component's local residual) to the rows of `dofs` at stage `stage`.
  void scatterResidual(std::size_t component, const std::vector<int>& dofs, const double* r, int stage, double weight);

  NonFiniteEntry firstNonFinite_;
  Eigen::VectorXd residual_;
  Eigen::VectorXd rowScale_;
  Eigen::SparseMatrix<double> tangent_;
  Flows flows_;
  std::vector<Flows> componentFlows_;
  bool keepComponentFlows_ = false;
  int stages_ = 1;
  int size_ = 0;  // of the model's state: the offset from one stage's unknowns to the next
  // per component and tangent block (component stages^2 + rowStage stages + columnStage):
  // (local column-major entry, position in tangent_ values) of its coupled pairs, by position
  std::vector<std::vector<std::pair<int, int>>> scatterMap_;
  // the matrix entries split into scatterParts_ ranges of about equal size: map m's pairs in
  // part p are [partStart_[m (parts + 1) + p], partStart_[m (parts + 1) + p + 1])
  int scatterParts_ = 1;
  std::vector<int> partStart_;
  // the first matrix entry of part p (the number of entries for p = scatterParts_)
  int partBound(int p) const {
    return static_cast<int>(static_cast<long long>(tangent_.nonZeros()) * p / scatterParts_);
  }
  // per prescribed motion and stage (k stages + l): its row, and its diagonal, in tangent_ values
  std::vector<std::vector<int>> prescribedRowEntries_;
  std::vector<int> prescribedDiagonal_;
  // per prescribed motion and stage m (k stages + m): the entry of column m in its last stage's
  // row (-1 where the pattern has none: that motion then keeps stage-value rows)
  std::vector<int> prescribedEndEntries_;
  bool hasEndEntries(std::size_t k) const {
    for (int m = 0; m < stages_; ++m)
      if (prescribedEndEntries_[k * stages_ + m] < 0) return false;
    return true;
  }
  // Components per batch, and the smallest batch evaluated in parallel (below it, starting the
  // threads costs more than they save: docs/performance.md, "Parallel assembly").
  static constexpr std::size_t kBatch = 256;
  static constexpr int kSmallestParallelBatch = 32;
  // Clearing the tangent counts as a batch of one slot per this many entries (a matrix of
  // kSmallestParallelBatch times as many entries is cleared in parallel).
  static constexpr long long kEntriesPerSlot = 4096;
  PassOrder everyComponent_;
  // the components that evaluate their stages together (Component::evaluatesStagesTogether),
  // and the others, which a residual-only stage pass evaluates one stage at a time
  std::vector<std::size_t> together_;
  PassOrder stageByStage_;
  // one local system per batch slot, over buffers sized for the largest component (a slot's
  // residual buffer holds one residual per stage, its flows one per stage)
  std::size_t largest_ = 0;
  std::vector<LocalSystem> locals_;
  std::vector<Flows> localFlows_;
  std::vector<double> localResidual_;
  std::vector<double> localTangent_;
};

}  // namespace mpx
