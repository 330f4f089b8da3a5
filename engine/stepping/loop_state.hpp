#pragma once
// Checkpoint and restart of the one-step time loops (fixed and adaptive steps): LoopState is
// everything a loop needs to continue a run bit for bit from an accepted step. A checkpoint
// also starts the linear solver afresh (new pivots, new analysis), because a factorisation's
// pivots cannot be saved through KLU's or UMFPACK's interface; a restart starts afresh as
// well, so both take the same path from there. A run with checkpoints therefore agrees with
// one without to round-off, and a restart from any of its checkpoints with it bit for bit.
#include "engine/core/component.hpp"

#include <Eigen/Dense>

#include <array>
#include <functional>

namespace mpx {

struct LoopState {
  // the last reported step, whose history row a restart reports again
  int step = 0;
  double time = 0.0, dt = 0.0;
  Eigen::VectorXd state;
  Flows crossed;
  int newtonIterations = 0, cutbacks = 0;
  // the summary's running figures
  long totalNewtonIterations = 0, factorizations = 0;
  int totalCutbacks = 0, rejectedSteps = 0;
  double initialEnergy = 0.0, energyScale = 0.0, largestEnergyError = 0.0;
  double initialEntropy = 0.0, previousEntropy = 0.0, minEntropyProduction = 0.0;
  // the integrator's predictor: the last step, from predictorStart at predictorTime over predictorDt
  Eigen::VectorXd predictorStart, predictorEnd;
  double predictorTime = 0.0, predictorDt = 0.0;
  // adaptive steps: the next step to try, and the accepted states the error estimate uses
  // (the first order + 1 slots, oldest first; of these, the last errorHistoryCount are set)
  static constexpr int kMostErrorHistory = 5;
  double proposedStep = 0.0;
  int errorHistoryCount = 0;
  std::array<double, kMostErrorHistory> errorTimes{};
  std::array<Eigen::VectorXd, kMostErrorHistory> errorStates;
};

struct Checkpointing {
  int every = 0;                                // steps between checkpoints (0: none)
  std::function<void(const LoopState&)> write;  // empty: no checkpoints, not even on a stop request
  const LoopState* resume = nullptr;            // continue from here instead of the initial state
};

// When a loop writes a checkpoint: after the first step that reaches each multiple of `every`
// (adaptive steps may pass one by two, in a step doubling), and at a stop request.
class CheckpointSchedule {
 public:
  CheckpointSchedule(const Checkpointing& checkpoints, int lastStep)
      : enabled_(static_cast<bool>(checkpoints.write)), every_(checkpoints.every), next_(nextAfter(lastStep)) {}
  bool due(int step, bool interrupted) {
    if (!enabled_) return false;
    const bool periodic = every_ > 0 && step >= next_;
    if (periodic) next_ = nextAfter(step);
    return periodic || interrupted;
  }

 private:
  int nextAfter(int step) const { return every_ > 0 ? (step / every_ + 1) * every_ : 0; }
  bool enabled_;
  int every_, next_;
};

}  // namespace mpx
