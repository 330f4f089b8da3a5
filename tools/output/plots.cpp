#include "tools/output/plots.hpp"

#include "tools/output/gnuplot.hpp"

#include <fmt/format.h>
#include <fmt/os.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mpx {

namespace {

// A log axis cannot show an exact zero: plot it at this floor.
constexpr double kLogFloor = 1e-17;

std::string header(const std::filesystem::path& png, const std::string& title) {
  return fmt::format(
      "set terminal pngcairo size 960,640 font 'Sans,11'\n"
      "set output '{}'\nset title '{}' noenhanced\nset grid\nset key outside right top noenhanced\n"
      "unset logscale\n",
      png.string(), title);
}

// "plot 'f1' using ... title 'a', 'f2' ..." over the curves' data files
std::string plotCommand(const std::vector<std::filesystem::path>& files, const std::vector<std::string>& labels,
                        const std::string& columns, const std::string& style) {
  std::string command = "plot ";
  for (std::size_t i = 0; i < files.size(); ++i)
    command += fmt::format("{}'{}' using {} with {} title '{}'", i ? ", \\\n     " : "", files[i].string(), columns,
                           style, labels[i]);
  return command + "\n";
}

}  // namespace

void renderPlots(const std::filesystem::path& dir, const std::string& sceneName, double tEnd,
                 const std::vector<WorkPrecisionCurve>& workPrecision, const std::vector<TimeSeries>& series) {
  const std::filesystem::path data = dir / "plot_data";
  std::filesystem::create_directories(data);
  std::vector<std::filesystem::path> wpFiles, seriesFiles;
  std::vector<std::string> wpLabels, seriesLabels;
  bool energyErrors = false;
  for (const WorkPrecisionCurve& curve : workPrecision) {
    if (curve.points.empty()) continue;
    wpFiles.push_back(data / ("work_precision_" + curve.label + ".dat"));
    wpLabels.push_back(curve.label);
    auto out = fmt::output_file(wpFiles.back().string());
    for (const WorkPrecisionPoint& p : curve.points) {
      out.print("{:.6e} {:.6e} {:.6e}\n", p.cpu, std::max(p.error, kLogFloor), std::max(p.energyError, kLogFloor));
      energyErrors = energyErrors || !std::isnan(p.energyError);
    }
  }
  for (std::size_t i = 0; i < series.size(); ++i) {
    seriesFiles.push_back(data / fmt::format("series_{}.dat", i));
    seriesLabels.push_back(series[i].label);
    auto out = fmt::output_file(seriesFiles.back().string());
    for (const SeriesPoint& p : series[i].points)
      out.print("{:.9e} {:.6e} {:.9e}\n", p.time, std::max(p.energyError, kLogFloor), p.entropyChange);
  }

  const std::filesystem::path script = dir / "plots.gp";
  {
    auto out = fmt::output_file(script.string());
    out.print("{}",
              header(dir / "work_precision.png", fmt::format("Work-precision, {} (t_end = {:g})", sceneName, tEnd)));
    out.print("set logscale xy\nset format x '10^{{%L}}'\nset format y '10^{{%L}}'\n");
    out.print(
        "set xlabel 'CPU time [s]'\nset ylabel 'relative error at t = t_{{end}} (positions, temperatures) [-]'\n");
    out.print("{}", plotCommand(wpFiles, wpLabels, "1:2", "linespoints lw 2 pt 7"));
    if (energyErrors) {
      out.print("{}", header(dir / "work_precision_energy.png",
                             fmt::format("Work-precision, energy at the end of loading, {}", sceneName)));
      out.print("set ylabel '|E - E_{{ref}}| / |E_{{ref}}| at the end of loading [-]'\n");
      out.print("{}", plotCommand(wpFiles, wpLabels, "1:3", "linespoints lw 2 pt 7"));
    }
    out.print("{}", header(dir / "energy_error.png", fmt::format("Energy balance error, {}", sceneName)));
    out.print("set logscale y\nset format y '10^{{%L}}'\nset format x '%g'\n");
    out.print("set xlabel 'time [s]'\nset ylabel '|E + D - W - Q - E_0| / largest energy so far [-]'\n");
    out.print("{}", plotCommand(seriesFiles, seriesLabels, "1:2", "lines lw 2"));
    out.print("{}", header(dir / "entropy.png", fmt::format("Entropy, {}", sceneName)));
    out.print("set format y '%g'\nset xlabel 'time [s]'\nset ylabel 'S(t) - S(0) [J/K]'\n");
    out.print("{}", plotCommand(seriesFiles, seriesLabels, "1:3", "lines lw 2"));
  }
  runGnuplot(script, dir / "gnuplot.log");
}

}  // namespace mpx
