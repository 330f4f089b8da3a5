#include "tools/output/budget_csv.hpp"

#include "tools/output/gnuplot.hpp"

#include "engine/core/input_error.hpp"

#include <fmt/format.h>
#include <fmt/os.h>
#include <fmt/ranges.h>

namespace mpx {

namespace {

std::FILE* create(const std::filesystem::path& path) {
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (!file) throw InputError(path.string() + ": cannot create the output file");
  return file;
}

}  // namespace

BudgetCsv::BudgetCsv(const std::filesystem::path& directory, const CompiledScene& scene, double interval)
    : directory_(directory), budget_(scene), schedule_(interval) {
  Measures initial;
  scene.model->measure(scene.model->initialState(), initial);
  initialEnergy_ = initial.energy;
  file_ = create(directory / "budget.csv.part");
  fmt::print(file_, "time,element,{}\n", fmt::join(ElementBudget::columnNames(), ","));
  std::filesystem::create_directories(directory / "plot_data");
  stack_ = create(directory / "plot_data" / "budget_stack.dat");
}

BudgetCsv::~BudgetCsv() {
  for (std::FILE* file : {file_, stack_})
    if (file) std::fclose(file);
}

void BudgetCsv::write(const StepRecord& record) {
  if (!schedule_.due(record.time)) return;
  const std::vector<ElementBudget::Row>& rows = budget_.rows(record);
  for (std::size_t g = 0; g < rows.size(); ++g)
    fmt::print(file_, "{:.17g},{},{:.17g}\n", record.time, budget_.groups()[g], fmt::join(rows[g], ","));
  // the stack: stored energies summed group by group, then the dissipated energy
  double sum = 0.0;
  fmt::print(stack_, "{:.9e}", record.time);
  for (const ElementBudget::Row& row : rows) fmt::print(stack_, " {:.9e}", sum += row[0]);
  fmt::print(stack_, " {:.9e} {:.9e}\n", sum + record.crossed.dissipated,
             initialEnergy_ + record.crossed.externalWork + record.crossed.boundaryHeat);
}

void BudgetCsv::finish() {
  std::fclose(file_);
  std::fclose(stack_);
  file_ = stack_ = nullptr;
  std::filesystem::rename(directory_ / "budget.csv.part", directory_ / "budget.csv");
  try {
    renderPicture();
  } catch (const std::runtime_error& error) {
    fmt::print(stderr, "metriplex: warning: no budget picture: {}\n", error.what());
  }
}

void BudgetCsv::renderPicture() const {
  const std::filesystem::path script = directory_ / "plot_data" / "budget.gp";
  const std::string data = gnuplotQuoted((directory_ / "plot_data" / "budget_stack.dat").string());
  const std::vector<std::string>& groups = budget_.groups();
  {
    auto out = fmt::output_file(script.string());
    out.print(
        "set terminal pngcairo size 960,640 font 'Sans,11'\nset output {}\nset title 'Energy budget by element' "
        "noenhanced\nset grid\nset key outside right top noenhanced\nset xlabel 'time [s]'\nset ylabel '[J]'\n"
        "set style fill solid 0.6 noborder\n",
        gnuplotQuoted((directory_ / "budget.png").string()));
    // layer g fills between the running sums g and g + 1 (column 2 + g is the sum up to group g)
    std::string plot = fmt::format("plot {} using 1:(0):2 with filledcurves title {}", data, gnuplotQuoted(groups[0]));
    for (std::size_t g = 1; g < groups.size(); ++g)
      plot +=
          fmt::format(", {} using 1:{}:{} with filledcurves title {}", data, g + 1, g + 2, gnuplotQuoted(groups[g]));
    const std::size_t dissipated = groups.size() + 2;
    plot += fmt::format(", {} using 1:{}:{} with filledcurves title 'dissipated'", data, dissipated - 1, dissipated);
    plot += fmt::format(", {} using 1:{} with lines lw 2 lc rgb 'black' title 'supplied: E_0 + W + Q'", data,
                        dissipated + 1);
    out.print("{}\n", plot);
  }
  runGnuplot(script, directory_ / "plot_data" / "gnuplot.log");
}

}  // namespace mpx
