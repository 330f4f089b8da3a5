#include "models/multibody/joint_builder.hpp"

#include <stdexcept>

namespace mpx {

namespace {
int dofCount(const Attachment& a) {
  return a.kind == Attachment::Kind::Body ? 12 : a.kind == Attachment::Kind::Point ? 3 : 0;
}

// Two unit vectors completing the unit axis w to an orthonormal frame.
std::pair<Vec3, Vec3> perpendiculars(const Vec3& w) {
  const Vec3 helper = std::abs(w.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 n1 = w.cross(helper).normalized();
  return {n1, w.cross(n1)};
}
}  // namespace

std::optional<JointType> jointTypeByName(const std::string& name) {
  if (name == "spherical") return JointType::Spherical;
  if (name == "revolute") return JointType::Revolute;
  if (name == "universal") return JointType::Universal;
  if (name == "cylindrical") return JointType::Cylindrical;
  if (name == "prismatic") return JointType::Prismatic;
  if (name == "fixed") return JointType::Fixed;
  if (name == "distance") return JointType::Distance;
  if (name == "planar") return JointType::Planar;
  return std::nullopt;
}

int constraintCount(JointType type) {
  switch (type) {
    case JointType::Spherical:
      return 3;
    case JointType::Revolute:
      return 5;
    case JointType::Universal:
      return 4;
    case JointType::Cylindrical:
      return 4;
    case JointType::Prismatic:
      return 5;
    case JointType::Fixed:
      return 6;
    case JointType::Distance:
      return 1;
    case JointType::Planar:
      return 3;
  }
  return 0;
}

bool coincidesPoints(JointType type) {
  return type == JointType::Spherical || type == JointType::Revolute || type == JointType::Universal ||
         type == JointType::Fixed;
}

JointBuilder::JointBuilder(const Attachment& a, const Attachment& b)
    : sides_{a, b}, ends_{a.firstPositionDof, b.firstPositionDof} {
  offset_[1] = dofCount(a);
  for (const Attachment& side : sides_)
    for (int i = 0; i < dofCount(side); ++i) dofs_.push_back(side.firstPositionDof + i);
}

JointBuilder::JointBuilder(const Attachment& body) : JointBuilder(body, Attachment{}) {
  ends_.second = body.firstPositionDof;
}

AffineVector JointBuilder::point(int side, const Vec3& worldPoint) const {
  const Attachment& s = sides_[side];
  AffineVector v;
  v.linear.setZero(3, static_cast<Eigen::Index>(dofs_.size()));
  if (s.kind == Attachment::Kind::Ground) {
    v.offset = worldPoint;
    return v;
  }
  v.linear.block<3, 3>(0, offset_[side]).setIdentity();
  // a body point is phi + X_i d_i with body coordinates X = D0^T (p - phi0)
  if (s.kind == Attachment::Kind::Body) {
    const Vec3 X = s.directors.transpose() * (worldPoint - s.position);
    for (int i = 0; i < 3; ++i) v.linear.block<3, 3>(0, offset_[side] + 3 + 3 * i) = X[i] * Mat3::Identity();
  }
  return v;
}

AffineVector JointBuilder::direction(int side, const Vec3& worldDirection) const {
  const Attachment& s = sides_[side];
  AffineVector v;
  v.linear.setZero(3, static_cast<Eigen::Index>(dofs_.size()));
  if (s.kind == Attachment::Kind::Ground) {
    v.offset = worldDirection;
    return v;
  }
  if (s.kind == Attachment::Kind::Point)
    throw std::invalid_argument("a mass point has no orientation: attach this joint to a body or the ground");
  const Vec3 a = s.directors.transpose() * worldDirection;
  for (int i = 0; i < 3; ++i) v.linear.block<3, 3>(0, offset_[side] + 3 + 3 * i) = a[i] * Mat3::Identity();
  return v;
}

AffineVector JointBuilder::difference(const AffineVector& u, const AffineVector& v) const {
  AffineVector d;
  d.linear = u.linear - v.linear;
  d.offset = u.offset - v.offset;
  return d;
}

QuadraticForm JointBuilder::component(const AffineVector& v, int k) const {
  const auto n = static_cast<Eigen::Index>(dofs_.size());
  return {ConstraintMatrix::Zero(n, n), v.linear.row(k).transpose(), v.offset[k]};
}

JointBuilder::DenseQuadratic JointBuilder::product(const AffineVector& u, const AffineVector& v) {
  // (U q + u0).(V q + v0) = 1/2 q.(U^T V + V^T U) q + (U^T v0 + V^T u0).q + u0.v0
  return {u.linear.transpose() * v.linear + v.linear.transpose() * u.linear,
          u.linear.transpose() * v.offset + v.linear.transpose() * u.offset, u.offset.dot(v.offset)};
}

QuadraticForm JointBuilder::dot(const AffineVector& u, const AffineVector& v, double target) const {
  const DenseQuadratic p = product(u, v);
  return {p.hessian, p.gradient, p.constant - target};
}

std::vector<QuadraticForm> JointBuilder::joint(JointType type, const JointGeometry& g) const {
  if (sides_[0].kind == Attachment::Kind::Ground && sides_[1].kind == Attachment::Kind::Ground)
    throw std::invalid_argument("a joint needs at least one side that moves");
  std::vector<QuadraticForm> forms;
  // named copies, not structured bindings: lambdas capture them (C++17)
  const std::pair<Vec3, Vec3> normals = perpendiculars(g.axis);
  const Vec3 &n1 = normals.first, &n2 = normals.second;
  const AffineVector gap = difference(point(0, g.anchor), point(1, g.anchor));
  auto coincide = [&] {
    for (int k = 0; k < 3; ++k) forms.push_back(component(gap, k));
  };
  // b's directions n1, n2 stay perpendicular to a's axis
  auto alignAxis = [&] {
    forms.push_back(dot(direction(0, g.axis), direction(1, n1), 0.0));
    forms.push_back(dot(direction(0, g.axis), direction(1, n2), 0.0));
  };
  // b's anchor point relative to a's: it slides along a's axis only, or stays in a's plane
  const AffineVector offset = difference(point(1, g.anchor), point(0, g.anchor));
  auto slideAlongAxis = [&] {
    forms.push_back(dot(offset, direction(0, n1), 0.0));
    forms.push_back(dot(offset, direction(0, n2), 0.0));
  };
  switch (type) {
    case JointType::Spherical:
      coincide();
      break;
    case JointType::Revolute:
      coincide(), alignAxis();
      break;
    case JointType::Universal:
      coincide();
      forms.push_back(dot(direction(0, g.axis), direction(1, g.axisB), g.axis.dot(g.axisB)));
      break;
    case JointType::Cylindrical:
      alignAxis(), slideAlongAxis();
      break;
    case JointType::Prismatic:
      alignAxis(), slideAlongAxis();
      forms.push_back(dot(direction(0, n1), direction(1, n2), 0.0));
      break;
    case JointType::Fixed:
      coincide();
      for (int i = 0; i < 3; ++i)
        forms.push_back(dot(direction(0, Vec3::Unit(i)), direction(1, Vec3::Unit((i + 1) % 3)), 0.0));
      break;
    case JointType::Planar:
      alignAxis();
      forms.push_back(dot(offset, direction(0, g.axis), 0.0));
      break;
    case JointType::Distance: {
      const AffineVector span = difference(point(0, g.anchor), point(1, g.anchorB));
      forms.push_back(dot(span, span, (g.anchor - g.anchorB).squaredNorm()));
      break;
    }
  }
  return forms;
}

std::vector<QuadraticForm> JointBuilder::coordinateInvariants(JointType type, const JointGeometry& g) const {
  const auto [n1, n2] = perpendiculars(g.axis);
  if (type == JointType::Revolute)
    return {dot(direction(0, n1), direction(1, n1), 0.0), dot(direction(0, n2), direction(1, n1), 0.0)};
  if (type == JointType::Prismatic) {
    const AffineVector offset = difference(point(1, g.anchor), point(0, g.anchor));
    return {dot(offset, direction(0, g.axis), 0.0)};
  }
  if (type == JointType::Spherical) {
    // s = vee(skew(R)) = sin(psi) n with R_ij = a_i . b_j: the relative rotation vector to first
    // order, s_x = (a_z.b_y - a_y.b_z)/2 and cyclic
    std::vector<QuadraticForm> forms;
    for (int k = 0; k < 3; ++k) {
      const int i = (k + 1) % 3, j = (k + 2) % 3;
      const DenseQuadratic s = product(direction(0, Vec3::Unit(j)), direction(1, Vec3::Unit(i)));
      const DenseQuadratic t = product(direction(0, Vec3::Unit(i)), direction(1, Vec3::Unit(j)));
      forms.emplace_back(0.5 * (s.hessian - t.hessian), 0.5 * (s.gradient - t.gradient),
                         0.5 * (s.constant - t.constant));
    }
    return forms;
  }
  throw std::invalid_argument("joint forces act on revolute, prismatic and spherical joints only");
}

std::vector<QuadraticForm> JointBuilder::rigidity() const {
  std::vector<QuadraticForm> forms;
  const Mat3& D = sides_[0].directors;
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j)
      forms.push_back(dot(direction(0, D.col(i)), direction(0, D.col(j)), i == j ? 1.0 : 0.0));
  return forms;
}

}  // namespace mpx
