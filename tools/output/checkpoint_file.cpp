#include "tools/output/checkpoint_file.hpp"

#include "engine/core/input_error.hpp"
#include "models/scene/input_file.hpp"
#include "tools/output/atomic_file.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>
#include <sstream>

namespace mpx {

namespace {

constexpr int kFormat = 2;  // 2: five error-history states (eem4 adaptive)

// Every field of a checkpoint, in file order, handed to visit(key, field): one list for the
// writer (const fields) and the reader.
template <class Identity, class Visit>
void visitIdentity(Identity& id, Visit&& visit) {
  visit("scene", id.scene);
  visit("scene_hash", id.sceneHash);
  visit("method", id.method);
  visit("adaptive", id.adaptive);
  visit("dofs", id.dofs);
  visit("dt", id.dt);
  visit("rtol", id.relativeTolerance);
  visit("atol", id.absoluteTolerance);
  visit("output_interval", id.outputInterval);
}

template <class State, class Visit>
void visitState(State& s, Visit&& visit) {
  visit("step", s.step);
  visit("time", s.time);
  visit("dt_last", s.dt);
  visit("state", s.state);
  visit("dissipated", s.crossed.dissipated);
  visit("external_work", s.crossed.externalWork);
  visit("boundary_heat", s.crossed.boundaryHeat);
  visit("boundary_entropy", s.crossed.boundaryEntropy);
  visit("newton_iterations", s.newtonIterations);
  visit("cutbacks", s.cutbacks);
  visit("total_newton_iterations", s.totalNewtonIterations);
  visit("factorizations", s.factorizations);
  visit("total_cutbacks", s.totalCutbacks);
  visit("rejected_steps", s.rejectedSteps);
  visit("initial_energy", s.initialEnergy);
  visit("energy_scale", s.energyScale);
  visit("largest_energy_error", s.largestEnergyError);
  visit("initial_entropy", s.initialEntropy);
  visit("previous_entropy", s.previousEntropy);
  visit("min_entropy_production", s.minEntropyProduction);
  visit("predictor_start", s.predictorStart);
  visit("predictor_end", s.predictorEnd);
  visit("predictor_time", s.predictorTime);
  visit("predictor_dt", s.predictorDt);
  visit("proposed_step", s.proposedStep);
  visit("error_history_count", s.errorHistoryCount);
  for (int k = 0; k < LoopState::kMostErrorHistory; ++k) {
    visit(fmt::format("error_time_{}", k), s.errorTimes[k]);
    visit(fmt::format("error_state_{}", k), s.errorStates[k]);
  }
}

// Writes one field per line.
struct FieldWriter {
  std::ostream& out;
  template <class Value>
  void operator()(const std::string& key, const Value& value) {
    out << key << ' ' << value << '\n';
  }
  void operator()(const std::string& key, const Eigen::VectorXd& values) {
    out << key << ' ' << values.size();
    for (double v : values) out << ' ' << v;
    out << '\n';
  }
};

// Reads the fields in order, each from its own line, and names file and line on any fault.
class FieldReader {
 public:
  FieldReader(std::string path, const std::string& text) : path_(std::move(path)), text_(text) {}

  void operator()(const std::string& key, std::string& value) {
    value = word(next(key));
    endOfLine(key);
  }
  void operator()(const std::string& key, bool& value) {
    value = integer(next(key), 0, 1) == 1;
    endOfLine(key);
  }
  void operator()(const std::string& key, int& value) {
    value = static_cast<int>(integer(next(key), 0, INT32_MAX));
    endOfLine(key);
  }
  void operator()(const std::string& key, long& value) {
    value = integer(next(key), 0, INT64_MAX);
    endOfLine(key);
  }
  void operator()(const std::string& key, double& value) {
    value = number(next(key));
    endOfLine(key);
  }
  // a state vector holds every dof, or none (fixed steps keep no error history)
  void operator()(const std::string& key, Eigen::VectorXd& values) {
    std::istringstream& line = next(key);
    values.resize(integer(line, 0, INT32_MAX));
    if (values.size() != 0 && values.size() != dofs)
      fail(fmt::format("'{}' has {} values; the scene has {} dofs", key, values.size(), dofs));
    for (double& v : values) v = number(line);
    endOfLine(key);
  }
  int dofs = 0;  // set once the identity is read
  void fail(const std::string& what) const { throw InputError(path_, line_, what); }
  // a field read earlier is out of its range: name its line
  void failAt(const std::string& key, const std::string& what) const {
    throw InputError(path_, lines_.at(key), "'" + key + "' " + what);
  }
  void finish() {
    std::string rest;
    if (std::getline(text_, rest)) ++line_, fail("unexpected line after the last field");
  }

 private:
  std::istringstream& next(const std::string& key) {
    std::string line;
    do {
      if (!std::getline(text_, line)) {
        if (line_ > 0) fail("the file ends before field '" + key + "'");
        line_ = 1;
        fail("the file is empty");
      }
      ++line_;
    } while (!line.empty() && line[0] == '#');
    current_.clear();
    current_.str(line);
    std::string found;
    current_ >> found;
    if (found != key) fail("expected field '" + key + "', found '" + found.substr(0, 40) + "'");
    lines_[key] = line_;
    return current_;
  }
  void endOfLine(const std::string& key) {
    std::string extra;
    if (current_ >> extra) fail("unexpected '" + extra.substr(0, 40) + "' after the value of '" + key + "'");
  }
  std::string word(std::istringstream& line) {
    std::string value;
    if (!(line >> value)) fail("a value is missing");
    return value;
  }
  long integer(std::istringstream& line, long least, long most) {
    const std::string text = word(line);
    std::size_t used = 0;
    long value = 0;
    try {
      value = std::stol(text, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != text.size() || value < least || value > most)
      fail(fmt::format("'{}' is not an integer from {} to {}", text.substr(0, 40), least, most));
    return value;
  }
  double number(std::istringstream& line) {
    const std::string text = word(line);
    char* end = nullptr;
    const double value = std::strtod(text.c_str(), &end);
    if (end != text.c_str() + text.size() || !std::isfinite(value))
      fail("'" + text.substr(0, 40) + "' is not a finite number");
    return value;
  }

  std::string path_;
  std::istringstream text_;
  std::istringstream current_;
  int line_ = 0;
  std::map<std::string, int> lines_;  // where each field was read
};

}  // namespace

std::string hashOfFile(const std::string& path) {
  std::uint64_t hash = 14695981039346656037ull;
  for (unsigned char c : readInputFile(path, "scene file")) hash = (hash ^ c) * 1099511628211ull;
  return fmt::format("{:016x}", hash);
}

void writeCheckpoint(const std::string& path, const CheckpointIdentity& identity, const LoopState& state) {
  writeAtomically(path, [&](std::ostream& out) {
    out << fmt::format("# metriplex checkpoint after step {}: continue with metriplex run SCENE --restart FILE\n",
                       state.step);
    FieldWriter writer{out};
    writer("format", kFormat);
    visitIdentity(identity, writer);
    visitState(state, writer);
  });
}

LoopState readCheckpoint(const std::string& path, const CheckpointIdentity& expected) {
  FieldReader reader(path, readInputFile(path, "checkpoint file"));
  int format = 0;
  reader("format", format);
  if (format != kFormat)
    reader.fail(fmt::format("checkpoint format {}; this program reads format {}", format, kFormat));
  CheckpointIdentity found;
  visitIdentity(found, reader);
  // the checkpoint must come from this scene, method and step settings
  auto require = [&](bool same, const std::string& what) {
    if (!same) throw InputError(path + ": the checkpoint was written by a run with another " + what);
  };
  require(found.scene == expected.scene && found.sceneHash == expected.sceneHash,
          "scene (" + found.scene + ", file hash " + found.sceneHash + "; this one: " + expected.scene + ", " +
              expected.sceneHash + ")");
  require(found.method == expected.method && found.adaptive == expected.adaptive,
          fmt::format("integrator ({}{})", found.method, found.adaptive ? ", adaptive" : ""));
  require(found.dofs == expected.dofs,
          fmt::format("state size ({} dofs; this scene has {})", found.dofs, expected.dofs));
  require(found.dt == expected.dt, fmt::format("step (--dt {:.17g}; this run: {:.17g})", found.dt, expected.dt));
  require(
      found.relativeTolerance == expected.relativeTolerance && found.absoluteTolerance == expected.absoluteTolerance,
      fmt::format("tolerance (--rtol {:.17g} --atol {:.17g})", found.relativeTolerance, found.absoluteTolerance));
  reader.dofs = expected.dofs;
  require(found.outputInterval == expected.outputInterval,
          fmt::format("output interval (--output-interval {:.17g}, where adaptive steps land)", found.outputInterval));
  LoopState state;
  visitState(state, reader);
  reader.finish();
  // what a run writes: times, steps and scales are not negative, the states are whole
  if (state.errorHistoryCount > LoopState::kMostErrorHistory)
    reader.failAt("error_history_count", fmt::format("must be 0 to {}", LoopState::kMostErrorHistory));
  for (const auto& [key, value] : {std::pair<const char*, double>{"time", state.time},
                                   {"dt_last", state.dt},
                                   {"energy_scale", state.energyScale},
                                   {"predictor_time", state.predictorTime},
                                   {"predictor_dt", state.predictorDt},
                                   {"proposed_step", state.proposedStep}})
    if (value < 0.0) reader.failAt(key, "must not be negative");
  for (const auto& [key, values] : {std::pair<const char*, const Eigen::VectorXd*>{"state", &state.state},
                                    {"predictor_start", &state.predictorStart},
                                    {"predictor_end", &state.predictorEnd}})
    if (values->size() == 0) reader.failAt(key, "is empty");
  return state;
}

}  // namespace mpx
