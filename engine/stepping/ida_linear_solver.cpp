#include "engine/stepping/ida_linear_solver.hpp"

#include "engine/linear/sparse_lu.hpp"

#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <memory>

namespace mpx {

namespace {

struct Content {
  std::unique_ptr<SparseLu> lu;
  Eigen::SparseMatrix<double> matrix;  // the pattern, with the values of the last setup
  Eigen::VectorXd rhs;
};

Content& content(SUNLinearSolver solver) { return *static_cast<Content*>(solver->content); }

SUNLinearSolver_Type type(SUNLinearSolver) { return SUNLINEARSOLVER_DIRECT; }
SUNLinearSolver_ID id(SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; }
int initialize(SUNLinearSolver) { return SUNLS_SUCCESS; }

// A singular matrix is recoverable: IDA retries with a smaller step.
int setup(SUNLinearSolver solver, SUNMatrix a) {
  Content& c = content(solver);
  std::copy_n(SUNSparseMatrix_Data(a), c.matrix.nonZeros(), c.matrix.valuePtr());
  return c.lu->factorize(c.matrix, false) ? SUNLS_SUCCESS : SUNLS_LUFACT_FAIL;
}

int solve(SUNLinearSolver solver, SUNMatrix, N_Vector x, N_Vector b, realtype) {
  Content& c = content(solver);
  const double* in = N_VGetArrayPointer(b);
  std::copy(in, in + c.rhs.size(), c.rhs.data());
  c.lu->solve(c.rhs);
  std::copy(c.rhs.data(), c.rhs.data() + c.rhs.size(), N_VGetArrayPointer(x));
  return SUNLS_SUCCESS;
}

int release(SUNLinearSolver solver) {
  delete static_cast<Content*>(solver->content);
  solver->content = nullptr;
  SUNLinSolFreeEmpty(solver);
  return SUNLS_SUCCESS;
}

}  // namespace

SUNLinearSolver makeIdaLinearSolver(const Eigen::SparseMatrix<double>& pattern, SUNContext context) {
  SUNLinearSolver solver = SUNLinSolNewEmpty(context);
  auto* c = new Content{makeSparseLu(static_cast<int>(pattern.rows())), pattern, Eigen::VectorXd(pattern.rows())};
  solver->content = c;
  solver->ops->gettype = type;
  solver->ops->getid = id;
  solver->ops->initialize = initialize;
  solver->ops->setup = setup;
  solver->ops->solve = solve;
  solver->ops->free = release;
  return solver;
}

const char* idaLinearSolverName(SUNLinearSolver solver) { return content(solver).lu->name(); }

}  // namespace mpx
