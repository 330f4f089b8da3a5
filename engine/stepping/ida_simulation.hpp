#pragma once
// The SUNDIALS IDA baseline (run through IDAS, the same BDF solver with quadratures): the model's rate form F(t, z,
// zdot) = 0 (Component::rateLocal) integrated by variable-order, variable-step BDF with the analytic Jacobian dF/dz +
// cj dF/dzdot, factorised by Metriplex's condensed solver (engine/stepping/ida_linear_solver.hpp). Energies that
// cross the boundary (D' = dissipated power, W' = external power, Q' = boundary heat rate) are IDA quadratures:
// integrated along, outside the Newton system and the error test.
#include "engine/stepping/simulation.hpp"

namespace mpx {

struct IdaOptions {
  double relativeTolerance = 1e-6;
  // Times each dof's scale (Model::dofScale): the error of dof i is measured against
  // rtol |z_i| + atol scale_i. Set it equal to rtol (what the CLI does unless --atol is
  // given), so that a small component is judged relative to its scale rather than to zero.
  double absoluteTolerance = 1e-6;
  int maxOrder = 5;
  // The Newton matrix goes to Metriplex's condensed solver (velocities eliminated, then a dense
  // LU, KLU or UMFPACK by size: engine/linear/sparse_lu.hpp), or with this set to SUNDIALS' own
  // KLU on the whole matrix.
  bool sundialsKlu = false;
  // Metriplex's sparse LU: each correction turns the Newton matrix with the scene since it was
  // set up (engine/linear/corotation.hpp)
  bool corotate = true;
  double outputStep = 0.0;  // history rows at multiples of this
  double tEnd = 0.0;
};

// Same contract as simulate(): step 0 is the initial state, one record per output time; the
// summary carries IDA's statistics and, on failure, IDA's own message.
RunSummary simulateIda(const Model& model, const IdaOptions& options, const StepSink& sink,
                       const ProgressSink& progress = nullptr);

}  // namespace mpx
