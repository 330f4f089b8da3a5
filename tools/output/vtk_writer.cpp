#include "tools/output/vtk_writer.hpp"

#include "tools/output/atomic_file.hpp"

#include <stdexcept>

namespace mpx {

namespace {

constexpr int kVtkTetra = 10, kVtkHexahedron = 12;

// Text safe inside an XML attribute value.
std::string xmlEscaped(const std::string& text) {
  std::string escaped;
  for (char c : text) {
    switch (c) {
      case '&':
        escaped += "&amp;";
        break;
      case '<':
        escaped += "&lt;";
        break;
      case '>':
        escaped += "&gt;";
        break;
      case '"':
        escaped += "&quot;";
        break;
      default:
        escaped += c;
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

}  // namespace mpx
