#include "engine/stepping/ida_linear_solver.hpp"

#include "engine/linear/condensed_solver.hpp"
#include "engine/linear/corotation.hpp"

#include <idas/idas.h>
#include <nvector/nvector_serial.h>

#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <optional>

namespace mpx {

namespace {

struct Content {
  CondensedSolver solver;
  Eigen::SparseMatrix<double> matrix;      // the pattern, with the values of the last setup
  Eigen::VectorXd rhs, increment, turned;  // turned: the right-hand side in the anchor's frame
  // IDA keeps its Newton matrix over many steps: it turns with the scene (null: as it was),
  // from where it was set up if that was within a step (IDA's initial condition has no iterate)
  std::optional<Corotation> corotation;
  void* ida;
  bool anchored = false;
};

Content& content(SUNLinearSolver solver) { return *static_cast<Content*>(solver->content); }

// IDA's current iterate, where the Newton matrix is set up and each correction is asked for
// (null outside a step).
N_Vector currentIterate(void* ida) {
  N_Vector y = nullptr;
  return IDAGetCurrentY(ida, &y) == IDA_SUCCESS ? y : nullptr;
}
Eigen::Map<const Eigen::VectorXd> values(N_Vector y) { return {N_VGetArrayPointer(y), N_VGetLength(y)}; }

SUNLinearSolver_Type type(SUNLinearSolver) { return SUNLINEARSOLVER_DIRECT; }
SUNLinearSolver_ID id(SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; }
int initialize(SUNLinearSolver) { return SUNLS_SUCCESS; }

// A singular matrix is recoverable: IDA retries with a smaller step.
int setup(SUNLinearSolver solver, SUNMatrix a) {
  Content& c = content(solver);
  std::copy_n(SUNSparseMatrix_Data(a), c.matrix.nonZeros(), c.matrix.valuePtr());
  if (c.corotation) {
    const N_Vector y = currentIterate(c.ida);
    c.anchored = y != nullptr;
    if (c.anchored) c.corotation->anchor(values(y));
  }
  return c.solver.factorize(c.matrix, false) ? SUNLS_SUCCESS : SUNLS_LUFACT_FAIL;
}

int solve(SUNLinearSolver solver, SUNMatrix, N_Vector x, N_Vector b, realtype) {
  Content& c = content(solver);
  const double* in = N_VGetArrayPointer(b);
  std::copy(in, in + c.rhs.size(), c.rhs.data());
  // the condensed solver gives the Newton increment -A^{-1} b (turned from where A was set up)
  const N_Vector y = c.corotation && c.anchored ? currentIterate(c.ida) : nullptr;
  if (y) {
    c.corotation->follow(values(y));
    c.corotation->solve(c.solver, c.rhs, c.turned, c.increment);
  } else {
    c.solver.solve(c.rhs, c.increment);
  }
  double* out = N_VGetArrayPointer(x);
  for (Eigen::Index i = 0; i < c.increment.size(); ++i) out[i] = -c.increment[i];
  return SUNLS_SUCCESS;
}

int release(SUNLinearSolver solver) {
  delete static_cast<Content*>(solver->content);
  solver->content = nullptr;
  SUNLinSolFreeEmpty(solver);
  return SUNLS_SUCCESS;
}

}  // namespace

SUNLinearSolver makeIdaLinearSolver(const Model& model, const Eigen::SparseMatrix<double>& pattern, void* ida,
                                    bool corotate, SUNContext context) {
  SUNLinearSolver solver = SUNLinSolNewEmpty(context);
  auto* c = new Content{CondensedSolver(model.layout(), pattern),
                        pattern,
                        Eigen::VectorXd(pattern.rows()),
                        Eigen::VectorXd(pattern.rows()),
                        Eigen::VectorXd(pattern.rows()),
                        std::nullopt,
                        ida};
  if (corotate) c->corotation.emplace(model, 1);
  solver->content = c;
  solver->ops->gettype = type;
  solver->ops->getid = id;
  solver->ops->initialize = initialize;
  solver->ops->setup = setup;
  solver->ops->solve = solve;
  solver->ops->free = release;
  return solver;
}

std::string idaLinearSolverDescription(SUNLinearSolver solver) { return content(solver).solver.describe(); }

}  // namespace mpx
