#pragma once
// What the command-line tests share: the program's exit codes, a fresh directory per test,
// and runs of the built binary with their streams captured.
#include "support.hpp"

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace mpx::test::cli {

namespace fs = std::filesystem;

// The exit codes tools/metriplex.cpp promises.
constexpr int kExitSuccess = 0;
constexpr int kExitInvalidInput = 2;
constexpr int kExitSolverFailure = 3;

inline std::vector<std::string> splitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream stream(text);
  for (std::string line; std::getline(stream, line);) lines.push_back(line);
  return lines;
}

inline std::vector<std::string> splitFields(const std::string& row) {
  std::vector<std::string> fields;
  std::istringstream stream(row);
  for (std::string field; std::getline(stream, field, ',');) fields.push_back(field);
  return fields;
}

// Single quotes keep the shell from splitting or expanding a path.
inline std::string quoted(const fs::path& path) { return "'" + path.string() + "'"; }

// What one run of the binary did.
struct Invocation {
  int exitCode = -1;
  std::string out, err;
};

// Each test gets a fresh directory for its scene, its output and the captured streams.
class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "metriplex-cli-XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr) << "cannot create a temporary directory";
    dir_ = pattern;
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path writeScene(const std::string& xml) const {
    const fs::path path = dir_ / "scene.xml";
    std::ofstream(path) << xml;
    return path;
  }
  fs::path outDir() const { return dir_ / "out"; }

  // Run `launcher metriplex arguments` with stdout and stderr captured to files.
  Invocation metriplex(const std::string& arguments, const std::string& launcher = "") const {
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string command =
        launcher + quoted(METRIPLEX_BINARY) + " " + arguments + " > " + quoted(out) + " 2> " + quoted(err);
    const int status = std::system(command.c_str());
    Invocation result;
    result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    result.out = readFile(out);
    result.err = readFile(err);
    return result;
  }

  fs::path dir_;
};

}  // namespace mpx::test::cli
