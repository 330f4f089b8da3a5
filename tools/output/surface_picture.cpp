#include "tools/output/surface_picture.hpp"

#include "tools/output/atomic_file.hpp"
#include "tools/output/gnuplot.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace mpx {

namespace {

namespace fs = std::filesystem;

// Boundary faces as pm3d patches: each face a 2 x 2 grid of two scans (a triangle repeats its last corner), patches
// separated by two blank lines, the cell's value as the colour column.
void writeSurfacePatches(std::ostream& out, const Mesh& mesh, const std::vector<Vec3>& positions,
                         const std::vector<double>& cellScalar) {
  for (const CellFace& cellFace : boundaryCellFaces(mesh)) {
    const Face& face = cellFace.face;
    const int corners[4] = {face.nodes[0], face.nodes[1], face.nodes[face.count - 1], face.nodes[2]};
    for (int c = 0; c < 4; ++c) {
      const Vec3& x = positions[corners[c]];
      out << x.x() << ' ' << x.y() << ' ' << x.z() << ' ' << cellScalar[cellFace.cell] << '\n';
      if (c == 1) out << '\n';
    }
    out << "\n\n";
  }
}

}  // namespace

void renderSurfacePng(const std::string& pngPath, const Mesh& mesh, const std::vector<Vec3>& positions,
                      const std::vector<double>& cellScalar, const std::string& scalarName, const std::string& title) {
  if (positions.size() != mesh.nodes.size() || cellScalar.size() != mesh.cells.size())
    throw std::invalid_argument("renderSurfacePng: positions or cell values do not match the mesh");
  const fs::path workDir = pngPath + ".render";
  fs::create_directories(workDir);
  const std::string data = (workDir / "surface.dat").string(), script = (workDir / "render.gp").string();
  const std::string log = (workDir / "gnuplot.log").string();
  writeAtomically(data, [&](std::ostream& out) { writeSurfacePatches(out, mesh, positions, cellScalar); });
  // a constant field still needs a non-empty colour range
  auto [low, high] = std::minmax_element(cellScalar.begin(), cellScalar.end());
  const double lowest = cellScalar.empty() ? 0 : *low, highest = cellScalar.empty() ? 0 : *high;
  const double margin = highest > lowest ? 0 : 0.5 * std::max(1.0, std::abs(lowest));
  writeAtomically(script, [&](std::ostream& out) {
    out << "set terminal pngcairo noenhanced size 1000,800\n"
        << "set output " << gnuplotQuoted(pngPath) << "\n"
        << "set title " << gnuplotQuoted(title) << "\n"
        << "set cblabel " << gnuplotQuoted(scalarName) << "\n"
        << "set cbrange [" << lowest - margin << ":" << highest + margin << "]\n"
        << "set palette defined (0 '#440154', 0.25 '#3b528b', 0.5 '#21908d', 0.75 '#5dc963', 1 '#fde725')\n"
        << "set view 60, 30\nset view equal xyz\nset xyplane relative 0\nunset key\n"
        << "set xlabel 'x'\nset ylabel 'y'\nset zlabel 'z'\n"
        << "set pm3d depthorder border lc rgb '#202020' lw 0.5 lighting primary 0.4 specular 0.1\n"
        << "splot " << gnuplotQuoted(data) << " using 1:2:3:4 with pm3d\n";
  });
  runGnuplot(script, log);
  std::error_code ignored;
  fs::remove_all(workDir, ignored);
}

}  // namespace mpx
