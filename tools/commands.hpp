#pragma once
// The metriplex subcommands. Each validates all of its input before it writes anything and
// returns the process exit code; invalid input throws InputError (exit code 2).
#include "tools/session/run_session.hpp"

#include <exception>
#include <optional>
#include <string>
#include <vector>

namespace mpx {

inline constexpr int kExitInvalidInput = 2;
inline constexpr int kExitSolverFailure = 3;
inline constexpr int kExitInterrupted = 4;  // SIGINT or SIGTERM: stopped at a step boundary

// A run stopped by SIGINT or SIGTERM where the command cannot report it itself (bench).
struct RunInterrupted : std::exception {
  const char* what() const noexcept override { return "interrupted (SIGINT or SIGTERM)"; }
};

// One integrator; DIR/history.csv; exit 3 on a solver failure.
int runCommand(const RunRequest& request);
// Several integrators side by side; DIR/<integrator>/history.csv.
int compareCommand(const RunRequest& base, const std::vector<std::string>& integrators);

struct BenchRequest {
  std::string scene;
  std::vector<std::string> integrators;  // one-step schemes and/or ida
  std::vector<double> steps;             // empty: the scene's dt times 2, 1, 1/2, ... 1/16
  std::vector<double> tolerances;        // IDA rtol values
  int repeats = 3;
  std::optional<double> tEnd;
  std::string out;
};

// Work-precision sweep: DIR/work_precision.csv and PNG plots.
int benchCommand(const BenchRequest& request);

}  // namespace mpx
