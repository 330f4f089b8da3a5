#pragma once
// A quick PNG view of a deformed solid: its boundary surface coloured by a cell field,
// rendered with gnuplot.
#include "models/fe/mesh.hpp"

#include <string>
#include <vector>

namespace mpx {

// Render the boundary surface of the mesh at `positions` as a PNG with gnuplot (pngcairo, pm3d), coloured by a
// per-cell scalar (the colour of a boundary face is its cell's value), viewed from (az, el) = (60, 30)-ish with equal
// axis scaling, title `title`. Writes the gnuplot script and data into a temp dir next to the png (removed after
// success), runs `gnuplot` via std::system; throws std::runtime_error if gnuplot fails.
void renderSurfacePng(const std::string& pngPath, const Mesh& mesh, const std::vector<Vec3>& positions,
                      const std::vector<double>& cellScalar, const std::string& scalarName, const std::string& title);

}  // namespace mpx
