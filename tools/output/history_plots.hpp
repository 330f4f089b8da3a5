#pragma once
// `metriplex plot DIR`: PNGs of a run's DIR/history.csv, rendered by gnuplot: energy and the
// balance terms, entropy and its production, temperatures (where the scene has a thermal
// state) and constraint violation, over time.
#include <filesystem>
#include <vector>

namespace mpx {

// Writes DIR/history_plots.gp and renders DIR/energy.png, entropy.png, temperatures.png (if
// history.csv has temperature columns) and constraint_violation.png; returns the PNGs.
// Throws InputError if DIR has no readable history.csv, std::runtime_error if gnuplot fails.
std::vector<std::filesystem::path> renderHistoryPlots(const std::filesystem::path& dir);

}  // namespace mpx
