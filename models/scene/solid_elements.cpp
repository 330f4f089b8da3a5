// Finite-element solids and the loads, supports and joints that refer to their named surfaces
// (docs/scene-format.md).
#include "models/fe/heat_conduction.hpp"
#include "models/fe/mesh_generators.hpp"
#include "models/fe/shape_functions.hpp"
#include "models/fe/solid_inertia.hpp"
#include "models/lumped/external_force.hpp"
#include "models/scene/gmsh_reader.hpp"
#include "models/scene/scene_build.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace mpx {

namespace {

// Newton's scale of a viscous strain (dimensionless).
constexpr double kViscousStrainScale = 1.0;

// Where a solid's mesh comes from: a generator or a Gmsh file, moved by `offset`.
struct MeshSource {
  std::string kind;  // "lblock", "box" or a .msh path
  int level = 1;
  Vec3 origin = Vec3::Zero(), size = Vec3::Ones(), offset = Vec3::Zero();
  std::array<int, 3> cells = {1, 1, 1};
};

// Generated meshes have at most this many cells (the L-block at level 30 has 972 000).
constexpr double kLargestGeneratedMesh = 1e6;
// Cells of the L-block at level 1; level L has L^3 as many.
constexpr int kLBlockCells = 36;

// Read (and so mark as read) the mesh attributes of a <solid>.
MeshSource readMeshSource(ElementReader& in) {
  MeshSource source;
  source.kind = in.text("mesh");
  auto checkSize = [&](double cells) {
    if (cells > kLargestGeneratedMesh)
      in.fail(
          fmt::format("the mesh would have {:.3g} cells; at most {:.0f} are generated", cells, kLargestGeneratedMesh));
  };
  if (source.kind == "lblock") {
    source.level = in.count("level", 1, 1, 1000);
    checkSize(kLBlockCells * std::pow(source.level, 3));
  } else if (source.kind == "box") {
    source.origin = in.vector("origin", Vec3::Zero());
    source.size = in.vector("size", Vec3::Ones());
    const std::vector<double> cells = in.numbers("cells");
    if (cells.size() != 3) in.fail("cells needs three counts (x y z)");
    for (int k = 0; k < 3; ++k) {
      if (!(cells[k] >= 1) || cells[k] != std::floor(cells[k])) in.fail("cells must be positive integers");
      checkSize(cells[k]);
      source.cells[k] = static_cast<int>(cells[k]);
    }
    checkSize(static_cast<double>(source.cells[0]) * source.cells[1] * source.cells[2]);
    if (!(source.size.minCoeff() > 0.0)) in.fail("size must be positive in every direction");
  }
  source.offset = in.vector("offset", Vec3::Zero());
  return source;
}

Mesh buildMesh(const MeshSource& source, const std::string& sceneFile) {
  Mesh mesh;
  if (source.kind == "lblock")
    mesh = makeLBlockMesh(source.level);
  else if (source.kind == "box")
    mesh = makeBoxMesh(source.origin, source.size, source.cells);
  else
    mesh = readGmshMesh((std::filesystem::path(sceneFile).parent_path() / source.kind).string());
  for (Vec3& node : mesh.nodes) node += source.offset;
  return mesh;
}

int quadraturePointsOf(const Cell& cell) { return cell.type == CellType::Hex8 ? 8 : 1; }

std::vector<Vec3> cellNodes(const Mesh& mesh, const Cell& cell) {
  std::vector<Vec3> nodes;
  for (int a = 0; a < nodeCount(cell.type); ++a) nodes.push_back(mesh.nodes[cell.nodes[a]]);
  return nodes;
}

DofDemand declareSolid(ElementReader& in, SceneBuild& build) {
  const MeshSource source = readMeshSource(in);
  std::shared_ptr<const Mesh> mesh;
  try {
    mesh = std::make_shared<const Mesh>(buildMesh(source, in.element().where.file));
  } catch (const std::invalid_argument& error) {
    in.fail(error.what());
  } catch (const InputError& error) {
    in.fail(std::string("mesh ") + error.what());  // the mesh file's own line, and this element's
  }
  if (mesh->cells.empty()) in.fail("the mesh has no cells");
  build.meshOfSolid[&in.element()] = mesh;
  if (const std::string* name = in.element().find("name")) build.meshByName.emplace(*name, mesh);
  DofDemand demand{3 * static_cast<int>(mesh->nodes.size()), 0, 0, 0};
  if (in.has("viscosity"))
    for (const Cell& cell : mesh->cells) demand.internal += 6 * quadraturePointsOf(cell);
  if (in.has("heat_capacity")) demand.thermal = static_cast<int>(mesh->nodes.size());
  return demand;
}

void buildSolid(ElementReader& in, SceneBuild& build, DofRange& dofs) {
  const std::string name = build.declareName(in);
  if (const std::string problem = fileNameProblem(name); !problem.empty()) in.fail("solid name " + problem);
  readMeshSource(in);
  const std::shared_ptr<const Mesh> mesh = build.meshOfSolid.at(&in.element());
  std::shared_ptr<const HyperelasticMaterial> material;
  const std::string law = in.text("material", "neo_hooke");
  std::optional<ViscousBranch> branch;
  std::optional<ThermalMaterial> thermal;
  double density = 0.0;
  try {
    // elastic constants as Young's modulus and Poisson's ratio, or as the Lame constants
    const LameParameters lame = in.has("mu") ? LameParameters{in.nonNegative("lambda", 0.0), in.positive("mu")}
                                             : LameParameters::fromYoung(in.positive("young"), in.number("poisson"));
    thermal = readThermalMaterial(in, lame);
    if (law == "neo_hooke")
      material = std::make_shared<NeoHooke>(lame);
    else if (law == "svk")
      material = std::make_shared<SaintVenantKirchhoff>(lame);
    else
      in.fail("material must be 'neo_hooke' or 'svk', got '" + law + "'");
    density = in.positive("density");
    if (in.has("viscosity"))
      branch =
          ViscousBranch{{in.nonNegative("branch_lambda", 0.0), in.positive("branch_mu")}, in.positive("viscosity")};
  } catch (const std::invalid_argument& error) {
    in.fail(error.what());
  }

  // initial state: reference positions, a rigid velocity field plus an optional twist
  const int shift = build.velocityShift();
  const int first = dofs.take(Block::Position, 3 * static_cast<int>(mesh->nodes.size()));
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
    build.state.segment<3>(dof) = X;
    build.state.segment<3>(dof + shift) =
        velocity + angular.cross(X - center) + twist[0] * std::sin(M_PI * X.y() / twist[1]) * Vec3(X.z(), 0.0, -X.x());
    low = low.cwiseMin(X);
    high = high.cwiseMax(X);
  }
  build.keepPositionScale((high - low).norm());
  SolidPlacement placement{name, mesh, first, shift, {}, {}, {}};
  if (thermal) takeTemperatures(in, build, dofs, *thermal, placement);

  // one element and one inertia per cell; a node's kinematic rows belong to its first cell
  std::vector<bool> owned(mesh->nodes.size(), false);
  for (std::size_t c = 0; c < mesh->cells.size(); ++c) {
    const Cell& cell = mesh->cells[c];
    SolidElementSpec element{name + ".cell" + std::to_string(c), {}, shift, -1, {}, material, branch, thermal, {},
                             placement.thermalVariable};
    SolidInertiaSpec inertia{element.name + ".inertia", {}, shift, {}, {}, density, build.spec.gravity};
    for (int a = 0; a < nodeCount(cell.type); ++a) {
      element.positionDofs.push_back(first + 3 * cell.nodes[a]);
      if (thermal) element.thermalDofs.push_back(placement.thermalDofs[cell.nodes[a]]);
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
      element.firstInternalDof = dofs.take(Block::Internal, count);
      build.scale.segment(element.firstInternalDof, count).setConstant(kViscousStrainScale);
    }
    if (thermal && thermal->conductivity > 0.0)
      build.addComponent(std::make_unique<HeatConduction>(element.name + ".conduction", element.thermalDofs,
                                                          placement.thermalVariable, element.points,
                                                          thermal->conductivity));
    auto solidElement = std::make_unique<SolidElement>(std::move(element));
    placement.cells.push_back(solidElement.get());
    build.addComponent(std::move(solidElement));
    build.addComponent(std::make_unique<SolidInertia>(inertia));
  }
  build.solids.push_back(std::move(placement));
}

// Add one nodal force per entry of `forces` (node -> force), scaled by `profile`.
void addNodalForces(SceneBuild& build, const std::string& name, const SolidPlacement& solid,
                    const std::map<int, Vec3>& forces, const TimeFunction& profile) {
  for (const auto& [node, force] : forces) {
    const int dof = solid.firstPositionDof + 3 * node;
    build.addComponent(std::make_unique<ExternalForce>(name + ".node" + std::to_string(node), dof,
                                                       dof + solid.velocityShift, force, profile));
  }
}

void buildTraction(ElementReader& in, SceneBuild& build, DofRange&) {
  const std::string name = build.declareName(in);
  const SolidPlacement& solid = build.solidOf(in);
  const std::string surface = in.text("surface");
  const auto faces = solid.mesh->surfaces.find(surface);
  if (faces == solid.mesh->surfaces.end())
    in.fail("attribute 'surface': the mesh of '" + solid.name + "' has no surface '" + surface + "'");
  if (in.has("traction") == in.has("total_force"))
    in.fail("give exactly one of 'traction' (force per reference area) and 'total_force'");

  // consistent nodal loads: traction times int N_a dA, summed over the faces
  const std::map<int, double> nodeArea = surfaceNodeAreas(*solid.mesh, faces->second);
  double area = 0.0;
  for (const auto& [node, share] : nodeArea) area += share;
  const Vec3 traction =
      in.has("traction") ? in.vector("traction", Vec3::Zero()) : in.vector("total_force", Vec3::Zero()) / area;
  std::map<int, Vec3> forces;
  for (const auto& [node, share] : nodeArea) forces[node] = share * traction;
  addNodalForces(build, name, solid, forces, readProfile(in, build));
}

void buildBodyForce(ElementReader& in, SceneBuild& build, DofRange&) {
  const std::string name = build.declareName(in);
  const SolidPlacement& solid = build.solidOf(in);
  const Vec3 density = in.vector("force_density", Vec3::Zero());
  // consistent nodal loads: force per reference volume times int N_a dV
  std::map<int, Vec3> forces;
  for (const Cell& cell : solid.mesh->cells)
    for (const CellPoint& p : cellQuadrature(cell.type, cellNodes(*solid.mesh, cell), Integrand::Mass))
      for (int a = 0; a < nodeCount(cell.type); ++a) {
        auto [it, inserted] = forces.emplace(cell.nodes[a], Vec3::Zero());
        it->second += p.weight * p.values[a] * density;
      }
  addNodalForces(build, name, solid, forces, readProfile(in, build));
}

enum class MotionKind { Clamp, Velocity, Displacement };

void buildPrescribedMotion(ElementReader& in, SceneBuild& build, MotionKind kind) {
  const SolidPlacement& solid = build.solidOf(in);
  const std::vector<int> nodes = build.solidNodes(in, solid);
  const std::string directions = in.text("directions", "xyz");
  if (directions.empty() || directions.find_first_not_of("xyz") != std::string::npos)
    in.fail("directions must be letters from 'xyz', got '" + directions + "'");
  const bool clamp = kind == MotionKind::Clamp, displacement = kind == MotionKind::Displacement;
  const Vec3 amplitude = clamp ? Vec3::Zero() : in.vector(displacement ? "displacement" : "velocity", Vec3::Zero());
  const TimeFunction profile = clamp ? TimeFunction::constant(0.0) : readProfile(in, build);
  // the initial velocity that the motion starts with
  const Vec3 startVelocity = amplitude * (displacement ? profile.slope(0.0) : profile(0.0));
  std::vector<PrescribedMotion>& motions = build.prescribedMotions;
  const std::string declaredAt = in.where() + ": <" + in.tag() + ">";
  for (int node : nodes)
    for (char direction : directions) {
      const int k = direction - 'x';
      const int dof = solid.firstPositionDof + 3 * node + k + solid.velocityShift;
      // supports meeting at an edge may prescribe a dof twice: the same clamp is fine
      const auto same =
          std::find_if(motions.begin(), motions.end(), [&](const PrescribedMotion& p) { return p.dof == dof; });
      if (same != motions.end()) {
        if (clamp && same->amplitude == 0.0) continue;
        in.fail("node " + std::to_string(node) + " of '" + solid.name + "' already has a prescribed motion in " +
                direction);
      }
      motions.push_back({dof, amplitude[k], profile,
                         displacement ? PrescribedKind::Displacement : PrescribedKind::Velocity, declaredAt});
      build.state[dof] = startVelocity[k];
    }
}

// A spherical joint (3 constraints, 2 multipliers each) per node of the surface.
DofDemand declareSolidJoint(ElementReader& in, SceneBuild& build) {
  const std::string* solid = in.element().find("solid");
  const std::string* surface = in.element().find("surface");
  const auto mesh = solid ? build.meshByName.find(*solid) : build.meshByName.end();
  if (mesh == build.meshByName.end() || !surface || !build.takesMultipliers(in)) return {};
  try {
    return {0, 0, 0, 2 * 3 * static_cast<int>(mesh->second->nodesOf(*surface).size())};
  } catch (const std::out_of_range&) {
    return {};  // reported when the element is built
  }
}

void buildSolidJoint(ElementReader& in, SceneBuild& build, DofRange& dofs) {
  const std::string name = build.declareName(in);
  const SolidPlacement& solid = build.solidOf(in);
  const std::vector<int> nodes = build.solidNodes(in, solid);
  const Attachment to = build.attachment(in, "to");
  const ConstraintSettings settings = build.constraintSettings(in);
  // each node is held at its material point of the target (a spherical joint per node)
  for (int node : nodes) {
    const int dof = solid.firstPositionDof + 3 * node;
    const Attachment point{Attachment::Kind::Point, dof, build.state.segment<3>(dof), Mat3::Identity()};
    const JointBuilder builder(point, to);
    JointGeometry geometry;
    geometry.anchor = point.position;
    build.addConstraint(name + ".node" + std::to_string(node), builder, builder.joint(JointType::Spherical, geometry),
                        coincidesPoints(JointType::Spherical), settings, dofs);
  }
}

}  // namespace

const std::vector<ElementKind>& solidElementKinds() {
  static const std::vector<ElementKind> kinds = {
      {"solid", declareSolid, buildSolid},
      {"traction", nullptr, buildTraction},
      {"body_force", nullptr, buildBodyForce},
      {"clamp", nullptr,
       [](ElementReader& in, SceneBuild& b, DofRange&) { buildPrescribedMotion(in, b, MotionKind::Clamp); }},
      {"prescribed_velocity", nullptr,
       [](ElementReader& in, SceneBuild& b, DofRange&) { buildPrescribedMotion(in, b, MotionKind::Velocity); }},
      {"prescribed_displacement", nullptr,
       [](ElementReader& in, SceneBuild& b, DofRange&) { buildPrescribedMotion(in, b, MotionKind::Displacement); }},
      {"solid_joint", declareSolidJoint, buildSolidJoint},
  };
  return kinds;
}

}  // namespace mpx
