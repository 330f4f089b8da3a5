#include "models/fe/shape_functions.hpp"

#include <cmath>
#include <stdexcept>

namespace mpx {

namespace {

struct ReferencePoint {
  Vec3 xi;
  double weight;
};

// Values and xi-gradients of the trilinear hexahedron on [-1, 1]^3 (VTK node order).
void hexahedronShape(const Vec3& xi, ShapeValues& n, ShapeGradients& dn) {
  static constexpr double corner[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                          {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  for (int a = 0; a < 8; ++a) {
    const double f[3] = {1 + corner[a][0] * xi[0], 1 + corner[a][1] * xi[1], 1 + corner[a][2] * xi[2]};
    n[a] = f[0] * f[1] * f[2] / 8;
    dn(a, 0) = corner[a][0] * f[1] * f[2] / 8;
    dn(a, 1) = corner[a][1] * f[0] * f[2] / 8;
    dn(a, 2) = corner[a][2] * f[0] * f[1] / 8;
  }
}

// Values and xi-gradients of the linear tetrahedron with barycentric (1 - sum xi, xi).
void tetrahedronShape(const Vec3& xi, ShapeValues& n, ShapeGradients& dn) {
  n.setZero();
  dn.setZero();
  n[0] = 1 - xi.sum();
  n.segment<3>(1) = xi;
  dn.row(0).setConstant(-1);
  dn.block<3, 3>(1, 0).setIdentity();
}

std::vector<ReferencePoint> referenceRule(CellType type, Integrand integrand) {
  if (type == CellType::Hex8) {
    const double g = 1 / std::sqrt(3.0);
    std::vector<ReferencePoint> rule;
    for (int k = 0; k < 8; ++k) rule.push_back({Vec3(k & 1 ? g : -g, k & 2 ? g : -g, k & 4 ? g : -g), 1.0});
    return rule;
  }
  if (integrand == Integrand::Stiffness) return {{Vec3::Constant(0.25), 1.0 / 6}};
  // the 4-point rule, exact for quadratics
  const double a = 0.5854101966249685, b = 0.1381966011250105;
  return {{Vec3(b, b, b), 1.0 / 24}, {Vec3(a, b, b), 1.0 / 24}, {Vec3(b, a, b), 1.0 / 24}, {Vec3(b, b, a), 1.0 / 24}};
}

}  // namespace

std::vector<CellPoint> cellQuadrature(CellType type, const std::vector<Vec3>& nodes, Integrand integrand) {
  Eigen::Matrix<double, 3, kMaxCellNodes> x = Eigen::Matrix<double, 3, kMaxCellNodes>::Zero();
  for (std::size_t a = 0; a < nodes.size(); ++a) x.col(a) = nodes[a];
  std::vector<CellPoint> points;
  for (const ReferencePoint& p : referenceRule(type, integrand)) {
    CellPoint point;
    ShapeGradients dnDxi;
    if (type == CellType::Hex8)
      hexahedronShape(p.xi, point.values, dnDxi);
    else
      tetrahedronShape(p.xi, point.values, dnDxi);
    // dX/dxi and the chain rule dN/dX = dN/dxi (dX/dxi)^-1
    const Mat3 jacobian = x * dnDxi;
    const double det = jacobian.determinant();
    if (!(det > 0.0))
      throw std::domain_error("the cell is inverted or degenerate (det dX/dxi = " + std::to_string(det) + ")");
    point.gradients = dnDxi * jacobian.inverse();
    point.weight = p.weight * det;
    points.push_back(point);
  }
  return points;
}

}  // namespace mpx
