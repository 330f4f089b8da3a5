#pragma once
// A SUNDIALS linear solver over Metriplex's own condensed sparse solver (engine/linear/
// condensed_solver.hpp: velocities eliminated through the kinematic rows, then a dense LU, KLU
// or UMFPACK by size),
// so that IDA factorises its Newton matrix as the one-step integrators do: half the unknowns for
// mechanics, and UMFPACK with METIS for 3D solids, where SUNDIALS' KLU is 20-60 times slower
// (docs/performance.md).
#include "engine/core/model.hpp"

#include <Eigen/Sparse>

#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>

#include <string>

namespace mpx {

// The solver factorises compressed-column SUNSparseMatrix values whose pattern is `pattern`'s
// (IDA's Jacobian callback copies that matrix in), over the state layout of `model`, for the IDA
// instance `ida`; with `corotate`, each correction turns the Newton matrix with the scene since
// it was set up (engine/linear/corotation.hpp). Solves allocate nothing. Free it with
// SUNLinSolFree.
SUNLinearSolver makeIdaLinearSolver(const Model& model, const Eigen::SparseMatrix<double>& pattern, void* ida,
                                    bool corotate, SUNContext context);
// What a solver from makeIdaLinearSolver factorises ("270 of 540 unknowns factorised by KLU
// (velocities eliminated)", ...).
std::string idaLinearSolverDescription(SUNLinearSolver solver);

}  // namespace mpx
