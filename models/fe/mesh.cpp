#include "models/fe/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mpx {

namespace {

// Local faces in VTK/Gmsh order, listed so that their right-hand normals point out of a positive cell.
constexpr int kTetFaces[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
constexpr int kHexFaces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};

}  // namespace

int nodeCount(CellType type) { return type == CellType::Tet4 ? 4 : 8; }

std::array<int, 4> faceKey(const Face& face) {
  std::array<int, 4> key = face.nodes;
  if (face.count == 3) key[3] = -1;
  std::sort(key.begin(), key.end());
  return key;
}

std::vector<Face> cellFaces(const Cell& cell) {
  std::vector<Face> faces;
  if (cell.type == CellType::Tet4) {
    for (const auto& local : kTetFaces)
      faces.push_back({3, {cell.nodes[local[0]], cell.nodes[local[1]], cell.nodes[local[2]], -1}});
  } else {
    for (const auto& local : kHexFaces)
      faces.push_back({4, {cell.nodes[local[0]], cell.nodes[local[1]], cell.nodes[local[2]], cell.nodes[local[3]]}});
  }
  return faces;
}

std::vector<CellFace> boundaryCellFaces(const Mesh& mesh) {
  // a face shared by two cells is interior; count the uses of each face first
  std::map<std::array<int, 4>, int> uses;
  for (const Cell& cell : mesh.cells)
    for (const Face& face : cellFaces(cell)) ++uses[faceKey(face)];
  std::vector<CellFace> boundary;
  for (int c = 0; c < static_cast<int>(mesh.cells.size()); ++c)
    for (const Face& face : cellFaces(mesh.cells[c]))
      if (uses[faceKey(face)] == 1) boundary.push_back({face, c});
  return boundary;
}

std::vector<Face> Mesh::boundaryFaces() const {
  std::vector<Face> faces;
  for (const CellFace& cellFace : boundaryCellFaces(*this)) faces.push_back(cellFace.face);
  return faces;
}

std::vector<int> Mesh::nodesOf(const std::string& name) const {
  std::vector<int> result;
  if (auto surface = surfaces.find(name); surface != surfaces.end()) {
    for (const Face& face : surface->second)
      result.insert(result.end(), face.nodes.begin(), face.nodes.begin() + face.count);
  } else if (auto set = nodeSets.find(name); set != nodeSets.end()) {
    result = set->second;
  } else {
    throw std::out_of_range("the mesh has no surface or node set named '" + name + "'");
  }
  std::sort(result.begin(), result.end());
  result.erase(std::unique(result.begin(), result.end()), result.end());
  return result;
}

// int N_a dA over a face at reference coordinates: a third of the area per triangle node, a
// 2 x 2 Gauss rule on a bilinear quadrilateral.
namespace {
std::array<double, 4> faceNodeAreas(const Face& face, const std::vector<Vec3>& nodes) {
  std::array<double, 4> area = {0, 0, 0, 0};
  const auto& n = face.nodes;
  if (face.count == 3) {
    const double third = (nodes[n[1]] - nodes[n[0]]).cross(nodes[n[2]] - nodes[n[0]]).norm() / 6;
    area = {third, third, third, 0.0};
    return area;
  }
  const double g = 1 / std::sqrt(3.0);
  for (double xi : {-g, g})
    for (double eta : {-g, g}) {
      const double shape[4] = {(1 - xi) * (1 - eta) / 4, (1 + xi) * (1 - eta) / 4, (1 + xi) * (1 + eta) / 4,
                               (1 - xi) * (1 + eta) / 4};
      const Vec3 dXi = ((1 - eta) * (nodes[n[1]] - nodes[n[0]]) + (1 + eta) * (nodes[n[2]] - nodes[n[3]])) / 4;
      const Vec3 dEta = ((1 - xi) * (nodes[n[3]] - nodes[n[0]]) + (1 + xi) * (nodes[n[2]] - nodes[n[1]])) / 4;
      const double jacobian = dXi.cross(dEta).norm();
      for (int a = 0; a < 4; ++a) area[a] += shape[a] * jacobian;
    }
  return area;
}
}  // namespace

std::map<int, double> surfaceNodeAreas(const Mesh& mesh, const std::vector<Face>& faces) {
  std::map<int, double> nodeArea;
  for (const Face& face : faces) {
    const std::array<double, 4> share = faceNodeAreas(face, mesh.nodes);
    for (int a = 0; a < face.count; ++a) nodeArea[face.nodes[a]] += share[a];
  }
  return nodeArea;
}

}  // namespace mpx
