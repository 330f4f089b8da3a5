#pragma once
// Volume mesh of a finite-element solid: reference node coordinates, tet4/hex8 cells and the
// named cell, face and node sets that loads and supports refer to.
#include <Eigen/Dense>

#include <array>
#include <map>
#include <string>
#include <vector>

namespace mpx {

using Vec3 = Eigen::Vector3d;

enum class CellType { Tet4, Hex8 };

// Number of nodes of a cell: 4 or 8.
int nodeCount(CellType type);

// Gmsh/VTK node order; tet4 uses nodes[0..3].
struct Cell {
  CellType type;
  std::array<int, 8> nodes;
};

// A boundary face: tri3 (count 3) or quad4 (count 4), nodes ordered so that the right-hand rule gives the outward
// normal
struct Face {
  int count;
  std::array<int, 4> nodes;
};

struct Mesh {
  std::vector<Vec3> nodes;  // reference coordinates
  std::vector<Cell> cells;
  std::map<std::string, std::vector<int>> volumes;    // named cell sets (physical volumes)
  std::map<std::string, std::vector<Face>> surfaces;  // named face sets (physical surfaces)
  std::map<std::string, std::vector<int>> nodeSets;   // named node sets (physical points/curves, optional)

  // Sorted unique node indices of a named surface, or of a named node set; throws std::out_of_range with the name if
  // neither exists
  std::vector<int> nodesOf(const std::string& name) const;
  // All boundary faces of the volume mesh (faces used by one cell only), outward oriented
  std::vector<Face> boundaryFaces() const;
};

// The faces of one cell, outward oriented for a cell of positive volume: 4 triangles or 6 quads.
std::vector<Face> cellFaces(const Cell& cell);

// Orientation-free identity of a face: its sorted nodes, -1 filling a triangle's fourth slot.
std::array<int, 4> faceKey(const Face& face);

// int N_a dA of each node of `faces` at reference coordinates, summed over the faces (a third
// of the area per triangle node, a 2 x 2 Gauss rule on a bilinear quadrilateral).
std::map<int, double> surfaceNodeAreas(const Mesh& mesh, const std::vector<Face>& faces);

// A boundary face and the cell it belongs to.
struct CellFace {
  Face face;
  int cell;
};

// Boundary faces of the mesh with their cells, in cell order (what boundaryFaces() returns, plus the cell).
std::vector<CellFace> boundaryCellFaces(const Mesh& mesh);

}  // namespace mpx
