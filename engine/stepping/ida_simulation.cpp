#include "engine/stepping/ida_simulation.hpp"

#include "engine/linear/assembler.hpp"
#include "engine/stepping/ida_linear_solver.hpp"

#include <Eigen/SparseLU>

#include <idas/idas.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_klu.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace mpx {

namespace {

// The energies crossing the boundary, integrated as IDA quadratures (outside the Newton system
// and the error test): dissipated, external work, boundary heat, boundary entropy.
constexpr int kQuadratures = 4;
// Absolute tolerance of the multipliers (forces, in the model's units) in IDA's Newton test;
// they are left out of the error test, and the GGL multiplier mu stays at round-off, so a
// tolerance tied to the positions' would ask Newton to resolve noise.
constexpr double kMultiplierTolerance = 1.0;
// below this relative tolerance, the shortest first step as a fraction of the first output
// interval (setFirstStep)
constexpr double kTightTolerance = 1e-10;
constexpr double kFirstStepFloor = 1e-6;

// Owns the IDA memory, vectors, Jacobian and linear solver for one run.
class IdaProblem {
 public:
  IdaProblem(const Model& model, const IdaOptions& options);
  ~IdaProblem();
  IdaProblem(const IdaProblem&) = delete;
  IdaProblem& operator=(const IdaProblem&) = delete;

  // Consistent initial rates (and multipliers) for the initial state; false on failure.
  // IDACalcIC takes its step scale from the first output time.
  bool initialise(double firstOutput);
  // Integrate to tout; false on failure (see error()).
  bool advanceTo(double tout);
  const double* state() const { return N_VGetArrayPointer(y_); }
  // Dissipated energy, external work and boundary heat since t = 0, at the last output.
  Flows crossed() const;
  const std::string& error() const { return error_; }
  IdaStatistics statistics() const;
  // What factorises the Newton matrix, for the run summary.
  const std::string& linearSystem() const { return linearSystem_; }
  double lastStep() const;

 private:
  static int residual(realtype t, N_Vector y, N_Vector yp, N_Vector r, void* self);
  static int flows(realtype t, N_Vector y, N_Vector yp, N_Vector rates, void* self);
  static int jacobian(realtype t, realtype cj, N_Vector y, N_Vector yp, N_Vector r, SUNMatrix J, void* self, N_Vector,
                      N_Vector, N_Vector);
  static void errorHandler(int code, const char* module, const char* function, char* message, void* self);
  // F and alpha dF/dy + cj dF/dyp (alpha = cj = 0: the residual alone, for IDA's residual calls)
  void evaluate(double t, N_Vector y, N_Vector yp, double alpha, double cj);
  void setFirstStep(double firstOutput);
  void check(int flag, const char* call) const;

  const Model& model_;
  Assembler assembler_;
  Workspace workspace_;
  int modelSize_;
  double relativeTolerance_;
  SUNContext context_ = nullptr;
  N_Vector y_ = nullptr, yp_ = nullptr, id_ = nullptr, atol_ = nullptr, crossed_ = nullptr;
  SUNMatrix jacobian_ = nullptr;
  SUNLinearSolver linearSolver_ = nullptr;
  void* ida_ = nullptr;
  std::string error_;
  std::string linearSystem_;
};

IdaProblem::IdaProblem(const Model& model, const IdaOptions& options)
    : model_(model),
      assembler_(model, Component::LocalForm::Rate),
      workspace_(model.makeWorkspace()),
      modelSize_(model.layout().total()),
      relativeTolerance_(options.relativeTolerance) {
  const int n = modelSize_;
  check(SUNContext_Create(nullptr, &context_), "SUNContext_Create");
  y_ = N_VNew_Serial(n, context_);
  yp_ = N_VNew_Serial(n, context_);
  id_ = N_VNew_Serial(n, context_);
  atol_ = N_VNew_Serial(n, context_);
  double* y = N_VGetArrayPointer(y_);
  double* atol = N_VGetArrayPointer(atol_);
  for (int i = 0; i < n; ++i) {
    y[i] = model.initialState()[i];
    atol[i] = model.layout().blockOf(i) == Block::Multiplier ? kMultiplierTolerance
                                                             : options.absoluteTolerance * model.dofScale()[i];
  }
  N_VConst(0.0, yp_);
  // multipliers are algebraic (and left out of the error test: the GGL form has index 2);
  // every other unknown of the rate form is differential
  double* id = N_VGetArrayPointer(id_);
  const Layout& layout = model.layout();
  for (int i = 0; i < n; ++i) id[i] = layout.blockOf(i) == Block::Multiplier ? 0.0 : 1.0;
  crossed_ = N_VNew_Serial(kQuadratures, context_);
  N_VConst(0.0, crossed_);

  ida_ = IDACreate(context_);
  check(IDASetErrHandlerFn(ida_, errorHandler, this), "IDASetErrHandlerFn");
  check(IDAInit(ida_, residual, 0.0, y_, yp_), "IDAInit");
  check(IDASVtolerances(ida_, options.relativeTolerance, atol_), "IDASVtolerances");
  check(IDASetUserData(ida_, this), "IDASetUserData");
  check(IDASetId(ida_, id_), "IDASetId");
  check(IDASetSuppressAlg(ida_, SUNTRUE), "IDASetSuppressAlg");
  check(IDASetMaxOrd(ida_, options.maxOrder), "IDASetMaxOrd");
  check(IDASetMaxNumSteps(ida_, 1000000), "IDASetMaxNumSteps");
  check(IDAQuadInit(ida_, flows, crossed_), "IDAQuadInit");

  const auto nonZeros = static_cast<sunindextype>(assembler_.tangent().nonZeros());
  jacobian_ = SUNSparseMatrix(n, n, nonZeros, CSC_MAT, context_);
  if (options.sundialsKlu) {
    linearSolver_ = SUNLinSol_KLU(y_, jacobian_, context_);
    linearSystem_ = std::to_string(n) + " unknowns factorised by KLU (SUNDIALS)";
  } else {
    linearSolver_ = makeIdaLinearSolver(model, assembler_.tangent(), ida_, options.corotate, context_);
    linearSystem_ = idaLinearSolverDescription(linearSolver_);
  }
  check(IDASetLinearSolver(ida_, linearSolver_, jacobian_), "IDASetLinearSolver");
  check(IDASetJacFn(ida_, jacobian), "IDASetJacFn");
}

IdaProblem::~IdaProblem() {
  IDAFree(&ida_);
  if (linearSolver_) SUNLinSolFree(linearSolver_);
  if (jacobian_) SUNMatDestroy(jacobian_);
  for (N_Vector v : {y_, yp_, id_, atol_, crossed_})
    if (v) N_VDestroy(v);
  if (context_) SUNContext_Free(&context_);
}

void IdaProblem::check(int flag, const char* call) const {
  if (flag < 0) throw std::runtime_error(std::string("SUNDIALS ") + call + " failed: " + error_);
}

void IdaProblem::errorHandler(int code, const char*, const char* function, char* message, void* self) {
  if (code < 0) static_cast<IdaProblem*>(self)->error_ = std::string(function) + ": " + message;
}

void IdaProblem::evaluate(double t, N_Vector y, N_Vector yp, double alpha, double cj) {
  assembler_.clear(alpha != 0.0 || cj != 0.0);
  assembler_.addRate(model_, workspace_, {N_VGetArrayPointer(y), N_VGetArrayPointer(yp), t, alpha, cj}, 1.0);
  assembler_.imposeRateMotions(model_, N_VGetArrayPointer(y), N_VGetArrayPointer(yp), t, cj);
}

int IdaProblem::residual(realtype t, N_Vector y, N_Vector yp, N_Vector r, void* user) {
  auto& self = *static_cast<IdaProblem*>(user);
  self.evaluate(t, y, yp, 0.0, 0.0);
  double* out = N_VGetArrayPointer(r);
  const Eigen::VectorXd& modelResidual = self.assembler_.residual();
  std::copy(modelResidual.data(), modelResidual.data() + self.modelSize_, out);
  // a stop request ends IDASolve at once (an output interval can take long); a non-finite
  // residual is recoverable: IDA retries with a smaller step
  if (stopRequested()) return -1;
  return modelResidual.allFinite() ? 0 : 1;
}

int IdaProblem::jacobian(realtype t, realtype cj, N_Vector y, N_Vector yp, N_Vector, SUNMatrix J, void* user, N_Vector,
                         N_Vector, N_Vector) {
  auto& self = *static_cast<IdaProblem*>(user);
  self.evaluate(t, y, yp, 1.0, cj);
  const Eigen::SparseMatrix<double>& K = self.assembler_.tangent();
  const int n = self.modelSize_;
  sunindextype* colStart = SUNSparseMatrix_IndexPointers(J);
  sunindextype* rowIndex = SUNSparseMatrix_IndexValues(J);
  double* values = SUNSparseMatrix_Data(J);
  std::copy(K.outerIndexPtr(), K.outerIndexPtr() + n + 1, colStart);
  std::copy(K.innerIndexPtr(), K.innerIndexPtr() + K.nonZeros(), rowIndex);
  std::copy(K.valuePtr(), K.valuePtr() + K.nonZeros(), values);
  return 0;
}

int IdaProblem::flows(realtype t, N_Vector y, N_Vector yp, N_Vector rates, void* user) {
  auto& self = *static_cast<IdaProblem*>(user);
  self.evaluate(t, y, yp, 0.0, 0.0);
  const Flows& flows = self.assembler_.flows();
  double* out = N_VGetArrayPointer(rates);
  out[0] = flows.dissipated;
  out[1] = flows.externalWork;
  out[2] = flows.boundaryHeat;
  out[3] = flows.boundaryEntropy;
  return std::isfinite(out[0] + out[1] + out[2] + out[3]) ? 0 : 1;
}

Flows IdaProblem::crossed() const {
  const double* q = N_VGetArrayPointer(crossed_);
  return {q[0], q[1], q[2], q[3]};
}

bool IdaProblem::initialise(double firstOutput) {
  // IDACalcIC handles index 1 only, and its line search fails at tight tolerances (rtol 1e-12
  // on the two thermo-springs); then, and for every model with multipliers, one linear solve
  // from (rates, multipliers) = 0: differential rows F = 0, and for each algebraic row (no
  // rate, no multiplier in it) dF/dz . zdot = 0. That is exact where the rate form is linear
  // in the rates and multipliers, which smoothed joint friction (F tanh(rate / v_s)) is not:
  // a joint with friction that moves at t = 0 starts from linearised rates.
  if (!model_.layout().has(Block::Multiplier) && IDACalcIC(ida_, IDA_YA_YDP_INIT, firstOutput) >= 0 &&
      IDAGetConsistentIC(ida_, y_, yp_) >= 0) {
    setFirstStep(firstOutput);
    return true;
  }
  error_.clear();
  const Layout& layout = model_.layout();
  const int n = modelSize_;
  N_VConst(0.0, yp_);
  double* y = N_VGetArrayPointer(y_);
  for (int i = layout.offset(Block::Multiplier); i < n; ++i) y[i] = 0.0;
  evaluate(0.0, y_, yp_, 1.0, 0.0);  // alpha = 1, beta = 0: F and dF/dz
  const Eigen::VectorXd residual = assembler_.residual();
  const Eigen::SparseMatrix<double> dFdz = assembler_.tangent();
  assembler_.clear();
  assembler_.addRate(model_, workspace_, {y, N_VGetArrayPointer(yp_), 0.0, 0.0, 1.0}, 1.0);
  assembler_.imposeRateMotions(model_, y, N_VGetArrayPointer(yp_), 0.0, 1.0);  // alpha = 0, beta = 1: dF/dzdot
  const Eigen::SparseMatrix<double>& dFdzdot = assembler_.tangent();

  // unknown j: the rate of a differential dof, or the value of a multiplier
  auto algebraic = [&](int i) { return layout.blockOf(i) == Block::Multiplier; };
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::VectorXd rhs = -residual;
  // a row is algebraic when it has no rate in it
  std::vector<bool> hasRate(n, false);
  for (int col = 0; col < n; ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(dFdzdot, col); it; ++it)
      if (it.value() != 0.0) hasRate[it.row()] = true;
  // a row without rates that sees only multipliers states their values (a redundant
  // condition's lambda = 0): it is solved as it stands, not differentiated
  std::vector<bool> seesState(n, false);
  for (int col = 0; col < n; ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(dFdz, col); it; ++it)
      if (it.value() != 0.0 && !algebraic(col)) seesState[it.row()] = true;
  for (int col = 0; col < n; ++col) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(dFdz, col); it; ++it) {
      if (!hasRate[it.row()] && !algebraic(col)) entries.emplace_back(it.row(), col, it.value());  // dF_a/dz . zdot
      if ((hasRate[it.row()] || !seesState[it.row()]) && algebraic(col))
        entries.emplace_back(it.row(), col, it.value());  // multipliers
    }
    for (Eigen::SparseMatrix<double>::InnerIterator it(dFdzdot, col); it; ++it)
      if (hasRate[it.row()] && !algebraic(col)) entries.emplace_back(it.row(), col, it.value());
  }
  for (int i = 0; i < n; ++i)
    if (!hasRate[i] && seesState[i]) rhs[i] = 0.0;
  Eigen::SparseMatrix<double> system(n, n);
  system.setFromTriplets(entries.begin(), entries.end());
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu(system);
  if (lu.info() != Eigen::Success) {
    error_ = "consistent initial conditions: singular system (redundant constraints or inconsistent initial state?)";
    return false;
  }
  const Eigen::VectorXd solution = lu.solve(rhs);
  double* yp = N_VGetArrayPointer(yp_);
  for (int i = 0; i < n; ++i) (algebraic(i) ? y[i] : yp[i]) = solution[i];
  if (IDAReInit(ida_, 0.0, y_, yp_) < 0 || IDAQuadReInit(ida_, crossed_) < 0) return false;
  setFirstStep(firstOutput);
  return true;
}

void IdaProblem::setFirstStep(double firstOutput) {
  if (relativeTolerance_ >= kTightTolerance) return;
  // IDA's own first step is min(0.001 |t1 - t0|, 0.5 / ||y'||_WRMS). At tight tolerances on fast
  // motion (the heavy top at rtol 1e-12) that is about 1e-15 s, where the iteration matrix of
  // the index-2 constraints is too ill-conditioned for the corrector, and IDA fails at t = 0
  // with h down to 1e-22. Below kTightTolerance the first step is at least kFirstStepFloor of
  // the first output interval (the error test shortens it if it is too long); looser runs keep
  // IDA's choice, which the floor would cost steps (heavy top at rtol 1e-6: 116 against 72).
  const double* y = N_VGetArrayPointer(y_);
  const double* yp = N_VGetArrayPointer(yp_);
  const double* atol = N_VGetArrayPointer(atol_);
  double sum = 0.0;
  for (int i = 0; i < modelSize_; ++i) {
    const double weighted = yp[i] / (relativeTolerance_ * std::abs(y[i]) + atol[i]);
    sum += weighted * weighted;
  }
  const double rateNorm = std::sqrt(sum / modelSize_);
  const double idaStep = std::min(1e-3 * firstOutput, rateNorm > 0.0 ? 0.5 / rateNorm : INFINITY);
  if (idaStep < kFirstStepFloor * firstOutput) IDASetInitStep(ida_, kFirstStepFloor * firstOutput);
}

bool IdaProblem::advanceTo(double tout) {
  realtype reached = 0.0;
  assembler_.forgetNonFinite();
  if (IDASolve(ida_, tout, &reached, y_, yp_, IDA_NORMAL) >= 0 && IDAGetQuad(ida_, &reached, crossed_) >= 0)
    return true;
  // name the component whose residual went non-finite on the way, if one did
  char note[300];
  if (assembler_.describeNonFinite(model_, note, sizeof note) > 0) error_ += std::string("; ") + note;
  return false;
}

double IdaProblem::lastStep() const {
  realtype step = 0.0;
  IDAGetLastStep(ida_, &step);
  return step;
}

IdaStatistics IdaProblem::statistics() const {
  IdaStatistics s;
  IDAGetNumSteps(ida_, &s.steps);
  IDAGetNumResEvals(ida_, &s.residualEvaluations);
  IDAGetNumJacEvals(ida_, &s.jacobianEvaluations);
  IDAGetNumNonlinSolvIters(ida_, &s.nonlinearIterations);
  IDAGetNumErrTestFails(ida_, &s.errorTestFailures);
  IDAGetNumNonlinSolvConvFails(ida_, &s.convergenceFailures);
  return s;
}

}  // namespace

RunSummary simulateIda(const Model& model, const IdaOptions& options, const StepSink& sink,
                       const ProgressSink& progress) {
  RunSummary summary;
  IdaProblem ida(model, options);
  const int n = model.layout().total();
  const auto outputs = static_cast<int>(std::ceil(options.tEnd / options.outputStep - 1e-9));
  RunReporter reporter(model, summary, sink, progress, options.tEnd);
  auto fail = [&](int output, double t, const std::string& what) {
    summary.failed = true;
    summary.failedStep = output;
    summary.failedTime = t;
    summary.failure = what + ": " + ida.error();
  };
  if (!ida.initialise(std::min(options.outputStep, 0.01 * options.tEnd)))
    fail(0, 0.0, "consistent initial conditions failed");
  long previousIterations = 0, previousErrorTestFailures = 0;
  for (int k = 1; k <= outputs && !summary.failed; ++k) {
    const double tout = k == outputs ? options.tEnd : k * options.outputStep;
    if (!ida.advanceTo(tout)) {
      // a stop request within the interval: the run ends at the last output time
      if (stopRequested()) {
        summary.interrupted = true;
        summary.interruptedTime = reporter.last().time;
      } else {
        fail(k, reporter.last().time, "IDASolve failed");
      }
      break;
    }
    reporter.state() = Eigen::Map<const Eigen::VectorXd>(ida.state(), n);
    const IdaStatistics stats = ida.statistics();
    if (!reporter.report(k, tout, ida.lastStep(), ida.crossed(),
                         static_cast<int>(stats.nonlinearIterations - previousIterations),
                         static_cast<int>(stats.errorTestFailures - previousErrorTestFailures)))
      break;
    previousIterations = stats.nonlinearIterations;
    previousErrorTestFailures = stats.errorTestFailures;
  }
  reporter.finish();
  summary.ida = ida.statistics();
  summary.linearSystem = ida.linearSystem();
  summary.newtonIterations = summary.ida->nonlinearIterations;
  summary.cutbacks = static_cast<int>(summary.ida->errorTestFailures);
  return summary;
}

}  // namespace mpx
