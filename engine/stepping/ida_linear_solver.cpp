#include "engine/stepping/ida_linear_solver.hpp"

#include "engine/linear/condensed_solver.hpp"

#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>

namespace mpx {

namespace {

struct Content {
  CondensedSolver solver;
  Eigen::SparseMatrix<double> matrix;  // the pattern, with the values of the last setup
  Eigen::VectorXd rhs, increment;
};

Content& content(SUNLinearSolver solver) { return *static_cast<Content*>(solver->content); }

SUNLinearSolver_Type type(SUNLinearSolver) { return SUNLINEARSOLVER_DIRECT; }
SUNLinearSolver_ID id(SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; }
int initialize(SUNLinearSolver) { return SUNLS_SUCCESS; }

// A singular matrix is recoverable: IDA retries with a smaller step.
int setup(SUNLinearSolver solver, SUNMatrix a) {
  Content& c = content(solver);
  std::copy_n(SUNSparseMatrix_Data(a), c.matrix.nonZeros(), c.matrix.valuePtr());
  return c.solver.factorize(c.matrix, false) ? SUNLS_SUCCESS : SUNLS_LUFACT_FAIL;
}

int solve(SUNLinearSolver solver, SUNMatrix, N_Vector x, N_Vector b, realtype) {
  Content& c = content(solver);
  const double* in = N_VGetArrayPointer(b);
  std::copy(in, in + c.rhs.size(), c.rhs.data());
  // the condensed solver gives the Newton increment -A^{-1} b
  c.solver.solve(c.rhs, c.increment);
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

SUNLinearSolver makeIdaLinearSolver(const Layout& layout, const Eigen::SparseMatrix<double>& pattern,
                                    SUNContext context) {
  SUNLinearSolver solver = SUNLinSolNewEmpty(context);
  // IDA keeps a Newton matrix for many steps: its solves, not its factorisations, dominate
  auto* c = new Content{CondensedSolver(layout, pattern, false, kManySolvesSystem), pattern,
                        Eigen::VectorXd(pattern.rows()), Eigen::VectorXd(pattern.rows())};
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
