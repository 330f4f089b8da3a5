#pragma once
// One run of a scene, as `metriplex run`, `metriplex compare` and the Python module do it:
// validate every option and the scene first (InputError, nothing written), then integrate and
// write DIR/history.csv, bodies.csv, joints.csv, solid frames, summary.json and checkpoints.
#include "engine/stepping/method.hpp"
#include "models/scene/scene_loader.hpp"
#include "tools/output/checkpoint_file.hpp"

#include <filesystem>
#include <optional>
#include <string>

namespace mpx {

struct RunRequest {
  std::string scene;                // a scene file, or the label of `spec`
  const SceneSpec* spec = nullptr;  // a scene built in code instead of the file (must outlive prepareRun)
  std::string integrator;           // empty: the scene's default
  std::optional<double> dt, tEnd;
  std::string out;                      // empty: a directory under out/ named after the scene
  std::optional<double> frameInterval;  // bodies.csv and joints.csv rows; empty: every step
  bool adaptive = false;                // one-step schemes; also when the scene says so
  // IDA and adaptive steps; empty: the scene's
  std::optional<double> relativeTolerance, absoluteTolerance;
  // IDA only
  std::optional<int> maxOrder;  // empty: the method's (ida-bdfK), else 5
  bool sundialsKlu = false;
  std::optional<double> outputStep;
  // one-step schemes
  int checkpointEvery = 0;  // steps between checkpoints in DIR/checkpoint.txt (0: only at a stop request)
  std::string restart;      // a checkpoint file to continue from
  bool urdfLimits = false;  // a .urdf scene: stops at its joints' position limits (as <urdf limits="true">)
  bool budget = false;      // DIR/budget.csv and budget.png: energy and entropy per element (one-step schemes)
};

// A run whose input has been fully validated: nothing is written before this exists.
struct PreparedRun {
  Method method;
  CompiledScene scene;
  MethodParameters parameters;
  std::filesystem::path out;
  double frameInterval = 0.0;  // bodies.csv, joints.csv and solid frames
  CheckpointIdentity identity;
  std::optional<LoopState> resume;  // --restart
  std::string thermalVariable() const;
};

// The default output directory is out/<scene>-<outSuffix>, or out/<scene>-<integrator> when
// outSuffix is empty. Throws InputError on any invalid option or scene.
PreparedRun prepareRun(const RunRequest& request, const std::string& outSuffix = "");

// What a run writes and whom it tells.
struct RunOutputs {
  bool files = true;         // DIR/history.csv and the rest; false: only `observe` sees the steps
  bool checkpoints = false;  // DIR/checkpoint.txt (one-step schemes)
  int checkpointEvery = 0;
  StepSink observe;  // every step, after the files
  ProgressSink progress;
};

struct RunResult {
  RunSummary summary;
  std::filesystem::path history;  // empty without files
};

RunResult executeRun(const PreparedRun& run, const RunOutputs& outputs);

// What the summary prints, as a JSON object (DIR/summary.json, the Python result's summary).
std::string summaryJson(const PreparedRun& run, const RunSummary& summary);

// Checkpoints of a run, under its output directory.
inline constexpr const char* kCheckpointFile = "checkpoint.txt";

}  // namespace mpx
