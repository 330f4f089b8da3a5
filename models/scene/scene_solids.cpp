// The finite-element elements of a scene: <solid> and the loads, supports and joints that
// refer to its named surfaces (docs/scene-format.md).
#include "models/scene/scene_compiler.hpp"

#include "models/lumped/external_force.hpp"
#include "models/scene/gmsh_reader.hpp"
#include "models/fe/mesh_generators.hpp"
#include "models/fe/shape_functions.hpp"
#include "models/fe/solid_inertia.hpp"

#include <cmath>
#include <filesystem>

namespace mpx {

namespace {

// Where a solid's mesh comes from: a generator or a Gmsh file, moved by `offset`.
struct MeshSource {
  std::string kind;  // "lblock", "box" or a .msh path
  int level = 1;
  Vec3 origin = Vec3::Zero(), size = Vec3::Ones(), offset = Vec3::Zero();
  std::array<int, 3> cells = {1, 1, 1};
};

// Read (and so mark as read) the mesh attributes of a <solid>.
MeshSource readMeshSource(ElementReader& in) {
  MeshSource source;
  source.kind = in.text("mesh");
  if (source.kind == "lblock") {
    source.level = in.count("level", 1);
    if (source.level < 1) in.fail("level must be at least 1");
  } else if (source.kind == "box") {
    source.origin = in.vector("origin", Vec3::Zero());
    source.size = in.vector("size", Vec3::Ones());
    const std::vector<double> cells = in.numbers("cells");
    if (cells.size() != 3) in.fail("cells needs three counts (x y z)");
    for (int k = 0; k < 3; ++k) {
      if (!(cells[k] >= 1) || cells[k] != std::floor(cells[k])) in.fail("cells must be positive integers");
      source.cells[k] = static_cast<int>(cells[k]);
    }
    if (!(source.size.minCoeff() > 0.0)) in.fail("size must be positive in every direction");
  }
  source.offset = in.vector("offset", Vec3::Zero());
  return source;
}

Mesh buildMesh(const MeshSource& source, const std::string& sceneFile) {
  Mesh mesh;
  if (source.kind == "lblock") mesh = makeLBlockMesh(source.level);
  else if (source.kind == "box") mesh = makeBoxMesh(source.origin, source.size, source.cells);
  else mesh = readGmshMesh((std::filesystem::path(sceneFile).parent_path() / source.kind).string());
  for (Vec3& node : mesh.nodes) node += source.offset;
  return mesh;
}

int quadraturePointsOf(const Cell& cell) { return cell.type == CellType::Hex8 ? 8 : 1; }

// int N_a dA over a face at reference coordinates: a third of the area per triangle node, a
// 2 x 2 Gauss rule on a bilinear quadrilateral.
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

std::vector<Vec3> cellNodes(const Mesh& mesh, const Cell& cell) {
  std::vector<Vec3> nodes;
  for (int a = 0; a < nodeCount(cell.type); ++a) nodes.push_back(mesh.nodes[cell.nodes[a]]);
  return nodes;
}

}  // namespace

void SceneCompiler::loadSolidMeshes() {
  for (const XMLElement* e = root_.FirstChildElement("solid"); e; e = e->NextSiblingElement("solid")) {
    ElementReader in(*e, file_);
    const std::string name = in.text("name");
    const MeshSource source = readMeshSource(in);
    try {
      solidMeshes_[name] = std::make_shared<const Mesh>(buildMesh(source, file_));
    } catch (const std::invalid_argument& error) {
      in.fail(error.what());
    } catch (const InputError& error) {
      in.fail(std::string("mesh ") + error.what());  // the mesh file's own line, and this element's
    }
    if (solidMeshes_[name]->cells.empty()) in.fail("the mesh has no cells");
  }
}

int SceneCompiler::solidPositionDofs(const XMLElement& element, int& internal) const {
  const Mesh& mesh = *solidMeshes_.at(element.Attribute("name"));
  if (element.Attribute("viscosity"))
    for (const Cell& cell : mesh.cells) internal += 6 * quadraturePointsOf(cell);
  return 3 * static_cast<int>(mesh.nodes.size());
}

int SceneCompiler::solidJointNodes(const XMLElement& element) const {
  const char* solid = element.Attribute("solid");
  const char* surface = element.Attribute("surface");
  const auto mesh = solid ? solidMeshes_.find(solid) : solidMeshes_.end();
  if (mesh == solidMeshes_.end() || !surface) return 0;  // reported when the element is read
  try {
    return static_cast<int>(mesh->second->nodesOf(surface).size());
  } catch (const std::out_of_range&) {
    return 0;
  }
}

void SceneCompiler::addSolid(ElementReader& in) {
  const std::string name = declareName(in);
  readMeshSource(in);
  const std::shared_ptr<const Mesh> mesh = solidMeshes_.at(name);
  std::shared_ptr<const HyperelasticMaterial> material;
  const std::string law = in.text("material", "neo_hooke");
  std::optional<ViscousBranch> branch;
  double density = 0.0;
  try {
    const LameParameters lame = LameParameters::fromYoung(in.positive("young"), in.number("poisson"));
    if (law == "neo_hooke") material = std::make_shared<NeoHooke>(lame);
    else if (law == "svk") material = std::make_shared<SaintVenantKirchhoff>(lame);
    else in.fail("material must be 'neo_hooke' or 'svk', got '" + law + "'");
    density = in.positive("density");
    if (in.has("viscosity"))
      branch = ViscousBranch{{in.nonNegative("branch_lambda", 0.0), in.positive("branch_mu")}, in.positive("viscosity")};
  } catch (const std::invalid_argument& error) {
    in.fail(error.what());
  }

  // initial state: reference positions, a rigid velocity field plus an optional twist
  const int first = layout_.dof(Block::Position, positionCount_);
  const int shift = layout_.offset(Block::Velocity) - layout_.offset(Block::Position);
  positionCount_ += 3 * static_cast<int>(mesh->nodes.size());
  Vec3 centroid = Vec3::Zero();
  for (const Vec3& x : mesh->nodes) centroid += x / static_cast<double>(mesh->nodes.size());
  const Vec3 velocity = in.vector("velocity", Vec3::Zero()), angular = in.vector("angular_velocity", Vec3::Zero());
  const Vec3 center = in.vector("center", centroid);
  std::vector<double> twist = in.has("twist") ? in.numbers("twist") : std::vector<double>{0.0, 1.0};
  if (twist.size() != 2 || !(twist[1] > 0.0)) in.fail("twist needs 'amplitude length' with a positive length");
  Vec3 low = mesh->nodes.front(), high = low;
  for (std::size_t n = 0; n < mesh->nodes.size(); ++n) {
    const Vec3& X = mesh->nodes[n];
    const int dof = first + 3 * static_cast<int>(n);
    state_.segment<3>(dof) = X;
    state_.segment<3>(dof + shift) =
        velocity + angular.cross(X - center) + twist[0] * std::sin(M_PI * X.y() / twist[1]) * Vec3(X.z(), 0.0, -X.x());
    low = low.cwiseMin(X);
    high = high.cwiseMax(X);
  }
  keepPositionScale((high - low).norm());

  // one element and one inertia per cell; a node's kinematic rows belong to its first cell
  int nextInternal = branch ? layout_.dof(Block::Internal, internalCount_) : -1;
  std::vector<bool> owned(mesh->nodes.size(), false);
  SolidOutput output{name, mesh, first, shift, {}};
  for (std::size_t c = 0; c < mesh->cells.size(); ++c) {
    const Cell& cell = mesh->cells[c];
    SolidElementSpec element{name + ".cell" + std::to_string(c), {}, shift, nextInternal, {}, material, branch};
    SolidInertiaSpec inertia{element.name + ".inertia", {}, shift, {}, {}, density, gravity_};
    for (int a = 0; a < nodeCount(cell.type); ++a) {
      element.positionDofs.push_back(first + 3 * cell.nodes[a]);
      inertia.ownsNode.push_back(!owned[cell.nodes[a]]);
      owned[cell.nodes[a]] = true;
    }
    inertia.positionDofs = element.positionDofs;
    try {
      element.points = cellQuadrature(cell.type, cellNodes(*mesh, cell), Integrand::Stiffness);
      inertia.points = cellQuadrature(cell.type, cellNodes(*mesh, cell), Integrand::Mass);
    } catch (const std::domain_error& error) {
      in.fail("cell " + std::to_string(c) + " of the mesh: " + error.what());
    }
    if (branch) {
      const int count = 6 * static_cast<int>(element.points.size());
      scale_.segment(nextInternal, count).setOnes();
      nextInternal += count;
      internalCount_ += count;
    }
    auto solidElement = std::make_unique<SolidElement>(std::move(element));
    output.cells.push_back(solidElement.get());
    components_.push_back(std::move(solidElement));
    components_.push_back(std::make_unique<SolidInertia>(inertia));
  }
  solids_.push_back(std::move(output));
}

const SolidOutput& SceneCompiler::solidOf(ElementReader& in) {
  const std::string name = in.text("solid");
  for (const SolidOutput& solid : solids_)
    if (solid.name == name) return solid;
  in.fail("attribute 'solid': no solid named '" + name + "' declared above this element");
}

std::vector<int> SceneCompiler::solidNodes(ElementReader& in, const SolidOutput& solid) {
  const std::string set = in.text("surface");
  try {
    return solid.mesh->nodesOf(set);
  } catch (const std::out_of_range&) {
    std::string known;
    for (const auto& [name, faces] : solid.mesh->surfaces) known += " " + name;
    for (const auto& [name, nodes] : solid.mesh->nodeSets) known += " " + name;
    in.fail("attribute 'surface': the mesh of '" + solid.name + "' has no surface or node set '" + set +
            "' (it has:" + known + ")");
  }
}

void SceneCompiler::addNodalForces(const std::string& name, const SolidOutput& solid,
                                   const std::map<int, Vec3>& forces, const TimeFunction& profile) {
  for (const auto& [node, force] : forces) {
    const int dof = solid.firstPositionDof + 3 * node;
    components_.push_back(
        std::make_unique<ExternalForce>(name + ".node" + std::to_string(node), dof, dof + solid.velocityShift, force, profile));
  }
}

void SceneCompiler::addTraction(ElementReader& in) {
  const std::string name = declareName(in);
  const SolidOutput& solid = solidOf(in);
  const std::string surface = in.text("surface");
  const auto faces = solid.mesh->surfaces.find(surface);
  if (faces == solid.mesh->surfaces.end()) in.fail("attribute 'surface': the mesh of '" + solid.name + "' has no surface '" + surface + "'");
  if (in.has("traction") == in.has("total_force"))
    in.fail("give exactly one of 'traction' (force per reference area) and 'total_force'");

  // consistent nodal loads: traction times int N_a dA, summed over the faces
  std::map<int, double> nodeArea;
  double area = 0.0;
  for (const Face& face : faces->second) {
    const std::array<double, 4> share = faceNodeAreas(face, solid.mesh->nodes);
    for (int a = 0; a < face.count; ++a) {
      nodeArea[face.nodes[a]] += share[a];
      area += share[a];
    }
  }
  const Vec3 traction = in.has("traction") ? in.vector("traction", Vec3::Zero()) : in.vector("total_force", Vec3::Zero()) / area;
  std::map<int, Vec3> forces;
  for (const auto& [node, share] : nodeArea) forces[node] = share * traction;
  addNodalForces(name, solid, forces, readProfile(in));
}

void SceneCompiler::addBodyForce(ElementReader& in) {
  const std::string name = declareName(in);
  const SolidOutput& solid = solidOf(in);
  const Vec3 density = in.vector("force_density", Vec3::Zero());
  // consistent nodal loads: force per reference volume times int N_a dV
  std::map<int, Vec3> forces;
  for (const Cell& cell : solid.mesh->cells)
    for (const CellPoint& p : cellQuadrature(cell.type, cellNodes(*solid.mesh, cell), Integrand::Mass))
      for (int a = 0; a < nodeCount(cell.type); ++a) {
        auto [it, inserted] = forces.emplace(cell.nodes[a], Vec3::Zero());
        it->second += p.weight * p.values[a] * density;
      }
  addNodalForces(name, solid, forces, readProfile(in));
}

void SceneCompiler::addPrescribedMotion(ElementReader& in, MotionKind kind) {
  const SolidOutput& solid = solidOf(in);
  const std::vector<int> nodes = solidNodes(in, solid);
  const std::string directions = in.text("directions", "xyz");
  if (directions.empty() || directions.find_first_not_of("xyz") != std::string::npos)
    in.fail("directions must be letters from 'xyz', got '" + directions + "'");
  const bool clamp = kind == MotionKind::Clamp, displacement = kind == MotionKind::Displacement;
  const Vec3 amplitude = clamp ? Vec3::Zero() : in.vector(displacement ? "displacement" : "velocity", Vec3::Zero());
  const TimeFunction profile = clamp ? TimeFunction::constant(0.0) : readProfile(in);
  // the initial velocity that the motion starts with
  const Vec3 startVelocity = amplitude * (displacement ? profile.slope(0.0) : profile(0.0));
  for (int node : nodes)
    for (char direction : directions) {
      const int k = direction - 'x';
      const int dof = solid.firstPositionDof + 3 * node + k + solid.velocityShift;
      // supports meeting at an edge may prescribe a dof twice: the same clamp is fine
      const auto same = std::find_if(prescribedMotions_.begin(), prescribedMotions_.end(),
                                     [&](const PrescribedMotion& p) { return p.dof == dof; });
      if (same != prescribedMotions_.end()) {
        if (clamp && same->amplitude == 0.0) continue;
        in.fail("node " + std::to_string(node) + " of '" + solid.name + "' already has a prescribed motion in " +
                direction);
      }
      prescribedMotions_.push_back({dof, amplitude[k], profile, displacement});
      state_[dof] = startVelocity[k];
    }
}

void SceneCompiler::addSolidJoint(ElementReader& in) {
  const std::string name = declareName(in);
  const SolidOutput& solid = solidOf(in);
  const std::vector<int> nodes = solidNodes(in, solid);
  const std::string target = in.text("to");
  const auto to = attachments_.find(target);
  if (to == attachments_.end()) in.fail("attribute 'to': no body, mass or anchor named '" + target + "' declared above");
  const ConstraintSettings settings = constraintSettings(in);
  // each node is held at its material point of the target (a spherical joint per node)
  for (int node : nodes) {
    const int dof = solid.firstPositionDof + 3 * node;
    const Attachment point{Attachment::Kind::Point, dof, state_.segment<3>(dof), Mat3::Identity()};
    const JointBuilder builder(point, to->second);
    JointGeometry geometry;
    geometry.anchor = point.position;
    addConstraint(name + ".node" + std::to_string(node), builder, builder.joint(JointType::Spherical, geometry), settings);
  }
}

}  // namespace mpx
