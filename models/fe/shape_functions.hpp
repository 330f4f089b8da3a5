#pragma once
// Shape functions and Gauss rules of the solid cells (trilinear hexahedron, linear
// tetrahedron), and their gradients mapped to the reference configuration of one cell.
#include "models/fe/mesh.hpp"

#include <Eigen/Dense>

#include <vector>

namespace mpx {

inline constexpr int kMaxCellNodes = 8;
// Shape function values (one per node) and their gradients, one row per node; rows past
// the cell's node count are zero, so 3 x 8 position matrices work for every cell type.
using Mat3 = Eigen::Matrix3d;
using ShapeValues = Eigen::Matrix<double, kMaxCellNodes, 1>;
using ShapeGradients = Eigen::Matrix<double, kMaxCellNodes, 3>;

// One quadrature point of a cell in its reference configuration: shape values, gradients
// dN/dX and the weight times det(dX/dxi).
struct CellPoint {
  ShapeValues values;
  ShapeGradients gradients;
  double weight;
};

// Which integrand a rule must integrate exactly: strain energy (full integration: 2x2x2
// points on a hexahedron, 1 on a tetrahedron) or the mass matrix (N_a N_b: 4 points on a
// tetrahedron).
enum class Integrand { Stiffness, Mass };

// The quadrature points of a cell at reference coordinates `nodes` (the cell's own nodes, in
// order). Throws std::domain_error if the cell is degenerate or inverted at a point.
std::vector<CellPoint> cellQuadrature(CellType type, const std::vector<Vec3>& nodes, Integrand integrand);

}  // namespace mpx
