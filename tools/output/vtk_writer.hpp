#pragma once
// Output of finite-element results for ParaView: VTK XML unstructured grids (.vtu) and time series (.pvd).
#include "models/fe/mesh.hpp"

#include <string>
#include <utility>
#include <vector>

namespace mpx {

// One field on points or cells: `components` values per point/cell, row after row.
struct VtkField {
  std::string name;
  int components;
  std::vector<double> values;
};

// Write a VTK XML UnstructuredGrid (.vtu, ASCII) of the mesh at the current positions (points = `positions`), with
// point fields and cell fields. Tet4 -> VTK_TETRA (10), Hex8 -> VTK_HEXAHEDRON (12). Written to path + ".part" and
// renamed, so a crash leaves no half-written file. Throws std::runtime_error naming the path if it cannot write, and
// std::invalid_argument if a position or field count does not match the mesh.
void writeVtu(const std::string& path, const Mesh& mesh, const std::vector<Vec3>& positions,
              const std::vector<VtkField>& pointFields, const std::vector<VtkField>& cellFields);

// A ParaView collection (.pvd) listing (time, file relative to the .pvd) — rewritten whole by write() (via .part +
// rename) so that it is valid after every frame.
class PvdSeries {
 public:
  explicit PvdSeries(std::string path);
  void add(double time, const std::string& relativeFile);
  void write() const;

 private:
  std::string path_;
  std::vector<std::pair<double, std::string>> frames_;  // (time, file relative to the .pvd)
};

}  // namespace mpx
