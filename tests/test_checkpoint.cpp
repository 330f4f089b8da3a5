// Checkpoint and restart from the command line (engine/stepping/loop_state.hpp): a restart
// from a checkpoint continues the run bit for bit, with fixed and adaptive steps and for every
// one-step scheme; a checkpoint that belongs to another run is refused with exit 2; a stop
// request writes one; IDA refuses both options.
#include "cli_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <string>
#include <vector>

namespace {

using namespace mpx::test::cli;
using mpx::test::readFile;

const std::string kScene = quoted(fs::path(mpx::test::scenePath("two_thermo_springs.xml")));

// The rows of a history from the one whose time field is `time` on (empty if none is).
std::vector<std::string> rowsFrom(const std::vector<std::string>& lines, const std::string& time) {
  for (std::size_t i = 1; i < lines.size(); ++i)
    if (lines[i].rfind(time + ",", 0) == 0) return {lines.begin() + static_cast<long>(i), lines.end()};
  return {};
}

// A scene, an integrator, the end time of the whole run, the checkpoint interval, further
// options, and the time of a load breakpoint that splits a step after the restart (none: "").
struct Restart {
  const char* scene;
  const char* integrator;
  double tEnd;
  int every;
  const char* options = "";
  const char* splitAt = "";
};

std::ostream& operator<<(std::ostream& os, const Restart& r) { return os << r.scene << " " << r.integrator; }

class CheckpointTest : public CliTest, public ::testing::WithParamInterface<Restart> {};

// A run stopped half-way leaves its last checkpoint; the restart from it to the whole run's
// end gives the whole run's rows from that step on, to the last bit, and the same summary
// (steps, Newton iterations, energy drift, entropy production)
TEST_P(CheckpointTest, ARestartContinuesTheRunBitForBit) {
  const Restart& c = GetParam();
  const std::string scene = quoted(fs::path(mpx::test::scenePath(c.scene)));
  const std::string options = " --integrator " + std::string(c.integrator) + " " + c.options + " --checkpoint-every " +
                              std::to_string(c.every) + " --t-end ";
  const std::string wholeEnd = std::to_string(c.tEnd), halfEnd = std::to_string(c.tEnd / 2);
  const fs::path whole = dir_ / "whole", half = dir_ / "half", restarted = dir_ / "restarted";
  const Invocation wholeRun = metriplex("run " + scene + options + wholeEnd + " --out " + quoted(whole));
  ASSERT_EQ(wholeRun.exitCode, kExitSuccess) << wholeRun.err;
  ASSERT_EQ(metriplex("run " + scene + options + halfEnd + " --out " + quoted(half)).exitCode, kExitSuccess);
  ASSERT_TRUE(fs::exists(half / "checkpoint.txt"));
  const Invocation restart = metriplex("run " + scene + options + wholeEnd + " --restart " +
                                       quoted(half / "checkpoint.txt") + " --out " + quoted(restarted));
  ASSERT_EQ(restart.exitCode, kExitSuccess) << restart.err;

  const std::vector<std::string> continued = splitLines(readFile(restarted / "history.csv"));
  ASSERT_GE(continued.size(), 3u);
  const std::string checkpointTime = splitFields(continued[1])[0];
  EXPECT_GT(std::stod(checkpointTime), c.tEnd / 4) << "the last checkpoint of the half run";
  const std::vector<std::string> original = rowsFrom(splitLines(readFile(whole / "history.csv")), checkpointTime);
  ASSERT_FALSE(original.empty()) << "no row at t = " << checkpointTime;
  if (*c.splitAt) {
    EXPECT_FALSE(rowsFrom(original, c.splitAt).empty()) << "no row at the breakpoint " << c.splitAt;
  }
  EXPECT_EQ(std::vector<std::string>(continued.begin() + 1, continued.end()), original);
  // the summaries agree but for the wall time
  auto withoutWallTime = [](const std::string& out) {
    std::string kept;
    for (const std::string& line : splitLines(out))
      if (line.find("wall time") == std::string::npos && line.find("history") == std::string::npos) kept += line + "\n";
    return kept;
  };
  EXPECT_EQ(withoutWallTime(restart.out), withoutWallTime(wholeRun.out));
}

// the thermo-springs (a thermal network), a closed loop under the augmented Lagrangian (KLU,
// whose pivots a checkpoint renews), a thermo-viscoelastic solid (internal variables), and a
// ramp load whose end (t = 2) splits a fixed step after the last checkpoint of the half run (t = 1.8)
INSTANTIATE_TEST_SUITE_P(Cli, CheckpointTest,
                         ::testing::Values(Restart{"two_thermo_springs.xml", "eem", 200, 37},
                                           Restart{"two_thermo_springs.xml", "eem-adaptive", 200, 37},
                                           Restart{"two_thermo_springs.xml", "midpoint", 200, 37},
                                           Restart{"two_thermo_springs.xml", "trapezoidal-adaptive", 200, 37},
                                           Restart{"two_thermo_springs.xml", "eem4-adaptive", 200, 37},
                                           Restart{"four_bar_revolute.xml", "eem", 0.5, 7},
                                           Restart{"four_bar_revolute.xml", "eem-adaptive", 0.5, 7},
                                           Restart{"lblock_thermoviscoelastic.xml", "eem", 0.5, 7},
                                           Restart{"damped_pendulum_spring.xml", "eem4", 4.2, 20, "--dt 0.03", "2"}),
                         [](const auto& info) {
                           std::string name = std::string(info.param.scene) + "_" + info.param.integrator;
                           for (char& ch : name)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return name;
                         });

// Exit 2 before anything is written, naming the checkpoint and what differs
TEST_F(CliTest, ACheckpointOfAnotherRunIsRefused) {
  const fs::path first = dir_ / "first";
  ASSERT_EQ(metriplex("run " + kScene + " --t-end 10 --checkpoint-every 5 --out " + quoted(first)).exitCode,
            kExitSuccess);
  const std::string checkpoint = quoted(first / "checkpoint.txt");
  struct Case {
    std::string options, mentions;
  };
  const Case cases[] = {
      {"--dt 0.05", "another step"},
      {"--integrator midpoint", "another integrator"},
      {"--adaptive", "another integrator"},
      {"--t-end 10", "not before t_end"},
  };
  for (const Case& c : cases) {
    const Invocation r =
        metriplex("run " + kScene + " " + c.options + " --restart " + checkpoint + " --out " + quoted(outDir()));
    EXPECT_EQ(r.exitCode, kExitInvalidInput) << c.options;
    EXPECT_NE(r.err.find(c.mentions), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(outDir())) << c.options;
  }
  const fs::path otherScene = writeScene(readFile(mpx::test::scenePath("two_thermo_springs.xml")) + "\n");
  const Invocation other =
      metriplex("run " + quoted(otherScene) + " --restart " + checkpoint + " --out " + quoted(outDir()));
  EXPECT_EQ(other.exitCode, kExitInvalidInput);
  EXPECT_NE(other.err.find("another scene"), std::string::npos) << other.err;

  // a damaged file: its line and what is wrong, before anything is written (a value that is no
  // number, not finite, out of its range, or followed by more text)
  const std::string text = readFile(first / "checkpoint.txt");
  struct Damage {
    std::string field, replacement, message;
  };
  const Damage damages[] = {
      {"time", "x", "'x' is not a finite number"},
      {"time", "-1", "'time' must not be negative"},
      {"time", "5 junk", "unexpected 'junk' after the value of 'time'"},
      {"initial_energy", "nan", "'nan' is not a finite number"},
      {"energy_scale", "-5", "'energy_scale' must not be negative"},
      {"error_history_count", "99", "'error_history_count' must be 0 to 5"},
  };
  for (const Damage& d : damages) {
    const std::size_t start = text.find("\n" + d.field + " ") + 1, end = text.find('\n', start);
    const int line = 1 + static_cast<int>(std::count(text.begin(), text.begin() + start, '\n'));
    std::ofstream(dir_ / "damaged.txt") << text.substr(0, start) + d.field + " " + d.replacement + text.substr(end);
    const Invocation damaged =
        metriplex("run " + kScene + " --restart " + quoted(dir_ / "damaged.txt") + " --out " + quoted(outDir()));
    EXPECT_EQ(damaged.exitCode, kExitInvalidInput) << d.field << " " << d.replacement;
    const std::string where = "damaged.txt:" + std::to_string(line) + ": " + d.message;
    EXPECT_NE(damaged.err.find(where), std::string::npos) << where << " in " << damaged.err;
    EXPECT_FALSE(fs::exists(outDir())) << d.field << " " << d.replacement;
  }
}

// Frame outputs after a restart: the checkpoint's row, then the whole run's output times only
TEST_F(CliTest, ARestartKeepsTheFrameTimesOfTheWholeRun) {
  const std::string scene = quoted(fs::path(mpx::test::scenePath("four_bar_revolute.xml")));
  const std::string options = " --checkpoint-every 7 --output-interval 0.1 --t-end ";
  const fs::path whole = dir_ / "whole", half = dir_ / "half", restarted = dir_ / "restarted";
  ASSERT_EQ(metriplex("run " + scene + options + "0.5 --out " + quoted(whole)).exitCode, kExitSuccess);
  ASSERT_EQ(metriplex("run " + scene + options + "0.25 --out " + quoted(half)).exitCode, kExitSuccess);
  ASSERT_EQ(metriplex("run " + scene + options + "0.5 --restart " + quoted(half / "checkpoint.txt") + " --out " +
                      quoted(restarted))
                .exitCode,
            kExitSuccess);
  auto times = [](const fs::path& bodies) {
    std::vector<std::string> found;
    for (const std::string& line : splitLines(readFile(bodies)))
      if (line.find(",crank,") != std::string::npos) found.push_back(splitFields(line)[0]);
    return found;
  };
  const std::vector<std::string> all = times(whole / "bodies.csv"), continued = times(restarted / "bodies.csv");
  ASSERT_GE(continued.size(), 2u);
  const std::vector<std::string> expected(std::find(all.begin(), all.end(), continued[1]), all.end());
  EXPECT_EQ(std::vector<std::string>(continued.begin() + 1, continued.end()), expected);
  EXPECT_EQ(expected.size(), 3u) << "t = 0.3, 0.4, 0.5";
}

// A run that ended between two multiples of dt (t = 1.05, dt 0.1), restarted to t = 2: every
// row's dt is the time since the row before, so the last step spans what remains to t_end
// (before, it took dt and was reported at t_end)
TEST_F(CliTest, ARestartFromBetweenStepsEndsOnTheEndTime) {
  const std::string options = " --dt 0.1 --checkpoint-every 1 --t-end ";
  const fs::path first = dir_ / "first", restarted = dir_ / "restarted";
  ASSERT_EQ(metriplex("run " + kScene + options + "1.05 --out " + quoted(first)).exitCode, kExitSuccess);
  ASSERT_EQ(metriplex("run " + kScene + options + "2 --restart " + quoted(first / "checkpoint.txt") + " --out " +
                      quoted(restarted))
                .exitCode,
            kExitSuccess);
  const std::vector<std::string> rows = splitLines(readFile(restarted / "history.csv"));
  std::vector<double> time, dt;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    if (rows[i].empty() || rows[i][0] == '#') continue;
    const std::vector<std::string> fields = splitFields(rows[i]);
    time.push_back(std::stod(fields[0]));
    dt.push_back(std::stod(fields[1]));
  }
  ASSERT_GE(time.size(), 3u);
  EXPECT_EQ(time.front(), 1.05);
  EXPECT_EQ(time.back(), 2.0);
  for (std::size_t k = 1; k < time.size(); ++k) EXPECT_NEAR(dt[k], time[k] - time[k - 1], 1e-12) << "row " << k;
}

TEST_F(CliTest, IdaRefusesCheckpoints) {
  for (const std::string option : {"--checkpoint-every 10", "--restart nothing.txt"}) {
    const Invocation r = metriplex("run " + kScene + " --integrator ida " + option + " --out " + quoted(outDir()));
    EXPECT_EQ(r.exitCode, kExitInvalidInput) << option;
    EXPECT_NE(r.err.find("'ida' cannot be checkpointed"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(outDir()));
  }
}

// SIGTERM: exit 4, a checkpoint of the last step, and a restart from it that reaches t_end
TEST_F(CliTest, AStopRequestWritesACheckpointToContinueFrom) {
  const fs::path history = outDir() / "history.csv.part";
  const std::string launcher =
      "sh -c 'while [ ! -s " + history.string() + " ]; do sleep 0.05; done; kill -TERM $PPID' & exec ";
  const Invocation stopped = metriplex("run " + kScene + " --t-end 1e6 --out " + quoted(outDir()), launcher);
  ASSERT_EQ(stopped.exitCode, 4) << stopped.err;
  EXPECT_NE(stopped.err.find("continue with --restart"), std::string::npos) << stopped.err;
  const std::vector<std::string> lines = splitLines(readFile(outDir() / "history.csv"));
  ASSERT_GE(lines.size(), 3u);
  const std::string lastTime = splitFields(lines[lines.size() - 2])[0];
  const std::string checkpoint = readFile(outDir() / "checkpoint.txt");
  EXPECT_NE(checkpoint.find("\ntime " + lastTime + "\n"), std::string::npos) << "the checkpoint is of the last row";

  fs::copy_file(outDir() / "checkpoint.txt", dir_ / "stop.txt");
  const Invocation resumed = metriplex("run " + kScene + " --t-end " + std::to_string(std::stod(lastTime) + 1.0) +
                                       " --restart " + quoted(dir_ / "stop.txt") + " --out " + quoted(outDir()));
  ASSERT_EQ(resumed.exitCode, kExitSuccess) << resumed.err;
  EXPECT_EQ(splitFields(splitLines(readFile(outDir() / "history.csv"))[1])[0], lastTime);
}

}  // namespace
