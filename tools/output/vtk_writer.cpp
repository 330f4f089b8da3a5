#include "tools/output/vtk_writer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace mpx {

namespace {

namespace fs = std::filesystem;

constexpr int kVtkTetra = 10, kVtkHexahedron = 12;

// Writes a file whole or not at all: into path + ".part", renamed over path once complete.
void writeAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  const std::string part = path + ".part";
  std::ofstream out(part);
  out.precision(std::numeric_limits<double>::max_digits10);
  if (out) write(out);
  out.close();
  std::error_code error;
  if (out) fs::rename(part, path, error);
  if (!out || error) {
    fs::remove(part, error);
    throw std::runtime_error("cannot write " + path);
  }
}

// Text safe inside an XML attribute value.
std::string xmlEscaped(const std::string& text) {
  std::string escaped;
  for (char c : text) {
    switch (c) {
      case '&': escaped += "&amp;"; break;
      case '<': escaped += "&lt;"; break;
      case '>': escaped += "&gt;"; break;
      case '"': escaped += "&quot;"; break;
      default: escaped += c;
    }
  }
  return escaped;
}

void checkFields(const std::vector<VtkField>& fields, size_t rows, const std::string& where) {
  for (const VtkField& field : fields)
    if (field.components < 1 || field.values.size() != rows * field.components)
      throw std::invalid_argument("VTK " + where + " field '" + field.name + "' has " +
                                  std::to_string(field.values.size()) + " values for " + std::to_string(rows) +
                                  " rows of " + std::to_string(field.components));
}

void writeDataArrays(std::ostream& out, const std::vector<VtkField>& fields) {
  for (const VtkField& field : fields) {
    out << "        <DataArray type=\"Float64\" Name=\"" << xmlEscaped(field.name) << "\" NumberOfComponents=\""
        << field.components << "\" format=\"ascii\">\n";
    for (size_t i = 0; i < field.values.size(); i += field.components) {
      out << "         ";
      for (int c = 0; c < field.components; ++c) out << ' ' << field.values[i + c];
      out << '\n';
    }
    out << "        </DataArray>\n";
  }
}

// Single-quoted for the shell: a quote inside becomes '\''.
std::string shellQuoted(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

// Single-quoted for gnuplot: a quote inside is doubled.
std::string gnuplotQuoted(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("''") : std::string(1, c);
  return quoted + "'";
}

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

void writeVtu(const std::string& path, const Mesh& mesh, const std::vector<Vec3>& positions,
              const std::vector<VtkField>& pointFields, const std::vector<VtkField>& cellFields) {
  if (positions.size() != mesh.nodes.size())
    throw std::invalid_argument("writeVtu: " + std::to_string(positions.size()) + " positions for " +
                                std::to_string(mesh.nodes.size()) + " nodes");
  checkFields(pointFields, mesh.nodes.size(), "point");
  checkFields(cellFields, mesh.cells.size(), "cell");
  writeAtomically(path, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\"?>\n"
        << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
        << "  <UnstructuredGrid>\n"
        << "    <Piece NumberOfPoints=\"" << positions.size() << "\" NumberOfCells=\"" << mesh.cells.size() << "\">\n"
        << "      <PointData>\n";
    writeDataArrays(out, pointFields);
    out << "      </PointData>\n      <CellData>\n";
    writeDataArrays(out, cellFields);
    out << "      </CellData>\n      <Points>\n"
        << "        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (const Vec3& x : positions) out << "          " << x.x() << ' ' << x.y() << ' ' << x.z() << '\n';
    out << "        </DataArray>\n      </Points>\n      <Cells>\n"
        << "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    for (const Cell& cell : mesh.cells) {
      out << "         ";
      for (int n = 0; n < nodeCount(cell.type); ++n) out << ' ' << cell.nodes[n];
      out << '\n';
    }
    out << "        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    long long offset = 0;
    for (const Cell& cell : mesh.cells) out << "          " << (offset += nodeCount(cell.type)) << '\n';
    out << "        </DataArray>\n        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
    for (const Cell& cell : mesh.cells)
      out << "          " << (cell.type == CellType::Tet4 ? kVtkTetra : kVtkHexahedron) << '\n';
    out << "        </DataArray>\n      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  });
}

PvdSeries::PvdSeries(std::string path) : path_(std::move(path)) {}

void PvdSeries::add(double time, const std::string& relativeFile) { frames_.emplace_back(time, relativeFile); }

void PvdSeries::write() const {
  writeAtomically(path_, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\"?>\n"
        << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n";
    for (const auto& [time, file] : frames_)
      out << "    <DataSet timestep=\"" << time << "\" group=\"\" part=\"0\" file=\"" << xmlEscaped(file) << "\"/>\n";
    out << "  </Collection>\n</VTKFile>\n";
  });
}

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
  if (std::system(("gnuplot " + shellQuoted(script) + " 2> " + shellQuoted(log)).c_str()) != 0) {
    std::ifstream messages(log);
    std::stringstream text;
    text << messages.rdbuf();
    throw std::runtime_error("gnuplot failed to render " + pngPath + " (script " + script + "): " + text.str());
  }
  std::error_code ignored;
  fs::remove_all(workDir, ignored);
}

}  // namespace mpx
