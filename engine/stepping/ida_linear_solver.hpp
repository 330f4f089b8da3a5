#pragma once
// A SUNDIALS linear solver over Metriplex's own sparse LU (KLU or UMFPACK, see
// engine/linear/sparse_lu.hpp), so that IDA factorises its Newton matrix with the same solver
// as the one-step integrators: UMFPACK with METIS for 3D solids, where SUNDIALS' KLU is 20-60
// times slower (docs/performance.md).
#include <Eigen/Sparse>

#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>

namespace mpx {

// The solver factorises compressed-column SUNSparseMatrix values whose pattern is `pattern`'s
// (IDA's Jacobian callback copies that matrix in); solves allocate nothing. Free it with
// SUNLinSolFree.
SUNLinearSolver makeIdaLinearSolver(const Eigen::SparseMatrix<double>& pattern, SUNContext context);
// The name of the factorisation a solver from makeIdaLinearSolver uses ("UMFPACK", ...).
const char* idaLinearSolverName(SUNLinearSolver solver);

}  // namespace mpx
