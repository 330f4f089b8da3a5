#include "tools/output/history_plots.hpp"

#include "tools/output/gnuplot.hpp"

#include "engine/core/input_error.hpp"

#include <fmt/format.h>
#include <fmt/os.h>

#include <fstream>
#include <sstream>

namespace mpx {

namespace {

std::vector<std::string> headerOf(const std::filesystem::path& history) {
  std::ifstream in(history);
  std::string line;
  if (!in || !std::getline(in, line) || line.rfind("time,", 0) != 0)
    throw InputError(history.string() + ": not a Metriplex history (no file, or no header starting with 'time,')");
  std::vector<std::string> names;
  std::stringstream stream(line);
  for (std::string name; std::getline(stream, name, ',');) names.push_back(name);
  return names;
}

// One PNG of some history columns against time.
struct Figure {
  std::string file, title, ylabel;
  std::vector<std::pair<std::string, std::string>> curves;  // gnuplot `using` expression, title
};

std::string column(const std::string& name) { return fmt::format("(column({}))", gnuplotQuoted(name)); }

}  // namespace

std::vector<std::filesystem::path> renderHistoryPlots(const std::filesystem::path& dir) {
  const std::filesystem::path history = dir / "history.csv";
  const std::vector<std::string> names = headerOf(history);
  const std::string balance = fmt::format("({}+{}-{}-{})", column("energy"), column("dissipated_energy"),
                                          column("external_work"), column("boundary_heat"));
  std::vector<Figure> figures = {{"energy.png",
                                  "Energy",
                                  "[J]",
                                  {{column("energy"), "stored energy E"},
                                   {column("dissipated_energy"), "dissipated D"},
                                   {column("external_work"), "external work W"},
                                   {column("boundary_heat"), "boundary heat Q"},
                                   {balance, "E + D - W - Q (constant if balanced)"}}},
                                 {"entropy.png",
                                  "Entropy",
                                  "[J/K]",
                                  {{column("entropy"), "entropy S"},
                                   {column("boundary_entropy"), "entropy brought in"},
                                   {column("entropy_production"), "entropy produced (never decreasing)"}}},
                                 {"constraint_violation.png",
                                  "Constraint violation",
                                  "max |Phi| [m]",
                                  {{column("constraint_violation"), "|Phi|"}}}};
  Figure temperatures{"temperatures.png", "Temperatures", "[K]", {}};
  for (const std::string& name : names)
    if (name.rfind("temperature_", 0) == 0) temperatures.curves.emplace_back(column(name), name.substr(12));
  if (!temperatures.curves.empty()) figures.push_back(temperatures);

  // columns are read by name, so the plots follow whatever columns the scene's history has
  const std::filesystem::path script = dir / "history_plots.gp";
  std::vector<std::filesystem::path> pictures;
  {
    auto out = fmt::output_file(script.string());
    out.print("set datafile separator comma\nset datafile columnheaders\n");
    for (const Figure& figure : figures) {
      pictures.push_back(dir / figure.file);
      out.print(
          "set terminal pngcairo size 960,640 font 'Sans,11'\nset output {}\nset title {} noenhanced\nset grid\n"
          "set key outside bottom center horizontal noenhanced\nset xlabel 'time [s]'\nset ylabel {}\n",
          gnuplotQuoted(pictures.back().string()), gnuplotQuoted(figure.title), gnuplotQuoted(figure.ylabel));
      std::string plot = "plot ";
      for (std::size_t i = 0; i < figure.curves.size(); ++i)
        plot += fmt::format("{}{} using 1:{} with lines lw 2 title {}", i ? ", " : "", gnuplotQuoted(history.string()),
                            figure.curves[i].first, gnuplotQuoted(figure.curves[i].second));
      out.print("{}\n", plot);
    }
  }
  runGnuplot(script, dir / "gnuplot.log");
  return pictures;
}

}  // namespace mpx
