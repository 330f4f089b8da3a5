#pragma once
// DIR/budget.csv (metriplex run --budget): time, element and the ElementBudget columns, one row
// per output time and element group; and DIR/budget.png, the stored energy of the elements
// stacked over time with the dissipated energy on top, against the energy supplied
// (E_0 + W + Q): where the balance holds, the stack's top is that line. Written as .part and
// renamed when the run ends; a picture gnuplot cannot render is a warning.
#include "tools/output/element_budget.hpp"
#include "tools/output/output_schedule.hpp"

#include <cstdio>
#include <filesystem>

namespace mpx {

class BudgetCsv {
 public:
  // interval <= 0: every step.
  BudgetCsv(const std::filesystem::path& directory, const CompiledScene& scene, double interval);
  ~BudgetCsv();
  BudgetCsv(const BudgetCsv&) = delete;
  BudgetCsv& operator=(const BudgetCsv&) = delete;

  void write(const StepRecord& record);
  void finish();

 private:
  void renderPicture() const;

  std::filesystem::path directory_;
  ElementBudget budget_;
  OutputSchedule schedule_;
  std::FILE* file_ = nullptr;
  std::FILE* stack_ = nullptr;  // plot_data/budget_stack.dat: time, running sums of the layers, supplied energy
  double initialEnergy_;
};

}  // namespace mpx
