// The per-element budget (metriplex run --budget): on every scene in scenes/, DIR/budget.csv
// summed over its element groups gives history.csv's energy, entropy, dissipated energy,
// external work, boundary heat, boundary entropy and entropy production at every output time,
// to round-off; each flow sits with the element that caused it; runs IDA cannot split are
// refused before anything is written; the budget plot's labels cannot leave their strings.
#include "support.hpp"

#include "tools/output/gnuplot.hpp"
#include "tools/session/run_session.hpp"

#include "engine/core/input_error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace mpx::test {
namespace {

namespace fs = std::filesystem;

using Table = std::vector<std::vector<std::string>>;

Table readCsv(const fs::path& path) {
  Table rows;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields;
    std::stringstream stream(line);
    for (std::string field; std::getline(stream, field, ',');) fields.push_back(field);
    rows.push_back(fields);
  }
  return rows;
}

int columnOf(const Table& table, const std::string& name) {
  const auto& header = table.front();
  const auto found = std::find(header.begin(), header.end(), name);
  return found == header.end() ? -1 : static_cast<int>(found - header.begin());
}

// A few steps of a scene with --budget, with the scene's integrator (EEM for an IDA scene).
fs::path runWithBudget(const std::string& scene, const fs::path& out) {
  const CompiledScene compiled = loadScene(scene);
  RunRequest request;
  request.scene = scene;
  request.integrator = compiled.settings.integrator == "ida" ? "eem" : "";
  request.tEnd = std::min(compiled.settings.tEnd, 4.0 * compiled.settings.dt);
  request.out = out.string();
  request.budget = true;
  const PreparedRun run = prepareRun(request);
  const RunResult result = executeRun(run, RunOutputs{});
  EXPECT_FALSE(result.summary.failed) << scene << ": " << result.summary.failure;
  return out;
}

class EveryScene : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryScene, BudgetSumsToTheHistoryTotals) {
  const fs::path out = fs::temp_directory_path() / ("metriplex-budget-" + fs::path(GetParam()).stem().string());
  fs::remove_all(out);
  runWithBudget(GetParam(), out);
  const Table history = readCsv(out / "history.csv"), budget = readCsv(out / "budget.csv");
  ASSERT_GT(history.size(), 2u);
  // the budget's rows, summed per output time; every step is an output time here
  std::map<double, std::vector<double>> sums;
  const int columns = static_cast<int>(budget.front().size()) - 2;
  // round-off is judged against the run's largest energy-like term (energies, dissipated,
  // work, heat) or entropy-like term (entropies, entropy brought in), of any group at any time,
  // as the summary judges the energy balance
  double energyScale = 0.0, entropyScale = 0.0;
  for (std::size_t r = 1; r < budget.size(); ++r) {
    auto& sum = sums.try_emplace(std::stod(budget[r][0]), columns, 0.0).first->second;
    for (int c = 0; c < columns; ++c) {
      const double value = std::stod(budget[r][2 + c]);
      sum[c] += value;
      const std::string& name = budget.front()[2 + c];
      double& scale = name.find("entropy") != std::string::npos ? entropyScale : energyScale;
      scale = std::max(scale, std::abs(value));
    }
  }
  ASSERT_EQ(sums.size(), history.size() - 1);
  for (std::size_t r = 1; r < history.size(); ++r) {
    const double time = std::stod(history[r][0]);
    ASSERT_TRUE(sums.count(time)) << "no budget at t = " << time;
    for (int c = 0; c < columns; ++c) {
      const std::string& name = budget.front()[2 + c];
      const double total = std::stod(history[r][columnOf(history, name)]);
      const double scale = name.find("entropy") != std::string::npos ? entropyScale : energyScale;
      // the same terms summed in another order
      EXPECT_NEAR(sums[time][c], total, 1e-12 * scale) << GetParam() << ", " << name << " at t = " << time;
    }
  }
  fs::remove_all(out);
}

std::vector<std::string> everyScene() {
  std::vector<std::string> scenes;
  for (const fs::path& dir : {fs::path(METRIPLEX_SCENES_DIR), fs::path(METRIPLEX_SCENES_DIR) / "urdf"})
    for (const auto& entry : fs::directory_iterator(dir))
      if (entry.path().extension() == ".xml" || entry.path().extension() == ".urdf")
        scenes.push_back(entry.path().string());
  std::sort(scenes.begin(), scenes.end());
  return scenes;
}

INSTANTIATE_TEST_SUITE_P(Scenes, EveryScene, ::testing::ValuesIn(everyScene()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = fs::path(info.param).stem().string();
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name + (fs::path(info.param).extension() == ".urdf" ? "_urdf" : "");
                         });

// the isothermal dashpot dissipates what the pendulum loses: D sits with the damper alone,
// and the bob's and spring's stored energies plus it stay at E_0
TEST(Budget, DissipationSitsWithTheDamper) {
  const fs::path out = fs::temp_directory_path() / "metriplex-budget-dashpot";
  fs::remove_all(out);
  runWithBudget(std::string(METRIPLEX_SCENES_DIR) + "/damped_pendulum_spring.xml", out);
  const Table budget = readCsv(out / "budget.csv");
  const int element = 1, dissipated = columnOf(budget, "dissipated_energy");
  double damperLoss = 0.0;
  for (std::size_t r = 1; r < budget.size(); ++r) {
    const double value = std::stod(budget[r][dissipated]);
    if (budget[r][element] == "dashpot")
      damperLoss = value;
    else
      EXPECT_EQ(value, 0.0) << budget[r][element];
  }
  EXPECT_GT(damperLoss, 0.0);
  fs::remove_all(out);
}

TEST(Budget, RefusedWhereFlowsPerElementAreNotKept) {
  RunRequest request;
  request.scene = std::string(METRIPLEX_SCENES_DIR) + "/two_thermo_springs.xml";
  request.budget = true;
  request.integrator = "ida";
  EXPECT_THROW(prepareRun(request), InputError);
  request.integrator = "eem";
  request.restart = "checkpoint.txt";
  EXPECT_THROW(prepareRun(request), InputError);
}

// A label reaches gnuplot as one string whatever it holds: a newline followed by '!' would run a
// shell command if it ended the string's line, and so would a command in backquotes; gnuplot
// prints the label back byte for byte.
TEST(Budget, PlotLabelsStayStrings) {
  const fs::path dir = fs::temp_directory_path() / "metriplex-gnuplot-label";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path touched = dir / "touched";
  const std::string label =
      "a\n!touch " + touched.string() + "\nb \"q\" 'r' \\z\t `touch " + touched.string() + "` end";
  {
    std::ofstream script(dir / "label.gp");
    script << "set print " << gnuplotQuoted((dir / "printed.txt").string()) << "\nprint " << gnuplotQuoted(label)
           << "\n";
  }
  runGnuplot(dir / "label.gp", dir / "label.log");
  EXPECT_FALSE(fs::exists(touched));
  std::ifstream printed(dir / "printed.txt");
  std::stringstream text;
  text << printed.rdbuf();
  EXPECT_EQ(text.str(), label + "\n");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace mpx::test
