#pragma once
// Checkpoint files: a one-step run's LoopState (engine/stepping/loop_state.hpp) as text, one
// "key values" line per field, doubles with 17 significant digits (they read back exactly).
// Written atomically; a restart checks that the checkpoint belongs to the run it continues.
#include "engine/stepping/loop_state.hpp"

#include <string>

namespace mpx {

// What a checkpoint must match to be continued: the scene (its name and a hash of its file),
// the method and its step settings, and the size of the state.
struct CheckpointIdentity {
  std::string scene;
  std::string sceneHash;
  std::string method;
  bool adaptive = false;
  int dofs = 0;
  double dt = 0.0;
  double relativeTolerance = 0.0;
  double absoluteTolerance = 0.0;
  double outputInterval = 0.0;  // adaptive steps land on its multiples
};

// FNV-1a of the file's bytes, in hex.
std::string hashOfFile(const std::string& path);

// Throws std::runtime_error naming the path if it cannot be written.
void writeCheckpoint(const std::string& path, const CheckpointIdentity& identity, const LoopState& state);

// Throws InputError (file:line: what is wrong) for a malformed file or one written by another
// run than `expected` describes.
LoopState readCheckpoint(const std::string& path, const CheckpointIdentity& expected);

}  // namespace mpx
