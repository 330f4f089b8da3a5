#include "models/fe/mesh_generators.hpp"

#include <functional>
#include <numeric>
#include <stdexcept>

namespace mpx {

namespace {

using GridLines = std::array<std::vector<double>, 3>;

// Grid lines of one axis: every interval between consecutive breakpoints split into `parts` equal pieces. The
// breakpoints themselves are kept exactly, so faces on them can be found by comparing coordinates.
std::vector<double> gridLines(const std::vector<double>& breakpoints, int parts) {
  std::vector<double> lines;
  for (size_t b = 0; b + 1 < breakpoints.size(); ++b)
    for (int k = 0; k < parts; ++k) lines.push_back(breakpoints[b] + (breakpoints[b + 1] - breakpoints[b]) * k / parts);
  lines.push_back(breakpoints.back());
  return lines;
}

// Hexahedra of the tensor grid whose centres `keep` accepts, with only the grid points they use as nodes (numbered
// x fastest, then y, then z). Neighbouring cells share grid points, so nodes are merged by construction.
Mesh makeGridMesh(const GridLines& lines, const std::function<bool(const Vec3&)>& keep) {
  const int nx = static_cast<int>(lines[0].size()), ny = static_cast<int>(lines[1].size());
  const int nz = static_cast<int>(lines[2].size());
  auto point = [&](int i, int j, int k) { return i + nx * (j + ny * k); };
  std::vector<std::array<int, 8>> kept;
  for (int k = 0; k + 1 < nz; ++k)
    for (int j = 0; j + 1 < ny; ++j)
      for (int i = 0; i + 1 < nx; ++i) {
        const Vec3 centre(lines[0][i] + lines[0][i + 1], lines[1][j] + lines[1][j + 1], lines[2][k] + lines[2][k + 1]);
        if (!keep(centre / 2)) continue;
        // VTK/Gmsh hex order: bottom face counter-clockwise seen from +z, then the top face above it
        kept.push_back({point(i, j, k), point(i + 1, j, k), point(i + 1, j + 1, k), point(i, j + 1, k),
                        point(i, j, k + 1), point(i + 1, j, k + 1), point(i + 1, j + 1, k + 1),
                        point(i, j + 1, k + 1)});
      }
  // number the used grid points compactly, in grid order
  std::vector<int> index(nx * ny * nz, -1);
  for (const auto& corners : kept)
    for (int p : corners) index[p] = 0;
  Mesh mesh;
  for (int p = 0; p < nx * ny * nz; ++p) {
    if (index[p] < 0) continue;
    index[p] = static_cast<int>(mesh.nodes.size());
    mesh.nodes.emplace_back(lines[0][p % nx], lines[1][p / nx % ny], lines[2][p / (nx * ny)]);
  }
  for (const auto& corners : kept) {
    Cell cell{CellType::Hex8, {}};
    for (int c = 0; c < 8; ++c) cell.nodes[c] = index[corners[c]];
    mesh.cells.push_back(cell);
  }
  mesh.volumes["all"].resize(mesh.cells.size());
  std::iota(mesh.volumes["all"].begin(), mesh.volumes["all"].end(), 0);
  return mesh;
}

// Boundary faces lying in the plane x[axis] == value.
std::vector<Face> facesOnPlane(const Mesh& mesh, const std::vector<Face>& boundary, int axis, double value) {
  std::vector<Face> faces;
  for (const Face& face : boundary) {
    bool onPlane = true;
    for (int n = 0; n < face.count; ++n) onPlane = onPlane && mesh.nodes[face.nodes[n]][axis] == value;
    if (onPlane) faces.push_back(face);
  }
  return faces;
}

}  // namespace

Mesh makeBoxMesh(const Vec3& origin, const Vec3& size, const std::array<int, 3>& cells) {
  GridLines lines;
  for (int axis = 0; axis < 3; ++axis) {
    if (cells[axis] < 1 || !(size[axis] > 0))
      throw std::invalid_argument("makeBoxMesh: every size must be positive and every cell count at least 1");
    lines[axis] = gridLines({origin[axis], origin[axis] + size[axis]}, cells[axis]);
  }
  Mesh mesh = makeGridMesh(lines, [](const Vec3&) { return true; });
  const std::vector<Face> boundary = mesh.boundaryFaces();
  const std::string axisNames[3] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    mesh.surfaces[axisNames[axis] + "0"] = facesOnPlane(mesh, boundary, axis, lines[axis].front());
    mesh.surfaces[axisNames[axis] + "1"] = facesOnPlane(mesh, boundary, axis, lines[axis].back());
  }
  mesh.surfaces["boundary"] = boundary;
  return mesh;
}

Mesh makeLBlockMesh(int level) {
  if (level < 1)
    throw std::invalid_argument("makeLBlockMesh: the level must be at least 1, got " + std::to_string(level));
  // coarse breakpoints: corner block and short leg in 1.5-wide cells, the 7-long leg in 5 slices
  const GridLines lines = {gridLines({0, 1.5, 3, 4.5, 6}, level), gridLines({0, 1.5, 3, 4.4, 5.8, 7.2, 8.6, 10}, level),
                           gridLines({0, 1.5, 3}, level)};
  Mesh mesh = makeGridMesh(lines, [](const Vec3& centre) { return centre.x() < 3 || centre.y() < 3; });
  mesh.surfaces["boundary"] = mesh.boundaryFaces();
  mesh.surfaces["load_y10"] = facesOnPlane(mesh, mesh.surfaces["boundary"], 1, 10.0);
  mesh.surfaces["load_x6"] = facesOnPlane(mesh, mesh.surfaces["boundary"], 0, 6.0);
  return mesh;
}

}  // namespace mpx
