// The finite-element mesh layer: generated box and L-block meshes have the stated counts, volumes and outward
// surfaces; Gmsh 2.2 and 4.1 files read into the same mesh with named sets and outward faces, and every kind of
// malformed file is rejected naming the file and line; VTK output parses as XML with the right sizes; the boundary
// renders to a PNG.
#include "engine/core/input_error.hpp"
#include "models/fe/mesh_generators.hpp"
#include "models/scene/gmsh_reader.hpp"
#include "tools/output/surface_picture.hpp"
#include "tools/output/vtk_writer.hpp"

#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

namespace mpx::test {
namespace {

namespace fs = std::filesystem;

// A fresh directory for the files of one test.
fs::path testDir(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / "metriplex_fe_mesh" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string writeFile(const fs::path& path, const std::string& text) {
  std::ofstream(path) << text;
  return path.string();
}

// Volume of a cell by 2x2x2 Gauss quadrature of det J for a hex (exact for trilinear maps), the triple product for a
// tet; also checks det J > 0 at every quadrature point.
double cellVolume(const Mesh& mesh, const Cell& cell) {
  auto x = [&](int local) { return mesh.nodes[cell.nodes[local]]; };
  if (cell.type == CellType::Tet4) return (x(1) - x(0)).cross(x(2) - x(0)).dot(x(3) - x(0)) / 6;
  const int sign[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                          {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  const double g = 1 / std::sqrt(3.0);
  double volume = 0;
  for (const auto& point : sign) {
    Eigen::Matrix3d jacobian = Eigen::Matrix3d::Zero();
    for (int a = 0; a < 8; ++a) {
      Vec3 dN;
      for (int d = 0; d < 3; ++d) {
        dN[d] = sign[a][d] / 8.0;
        for (int e = 0; e < 3; ++e)
          if (e != d) dN[d] *= 1 + sign[a][e] * point[e] * g;
      }
      jacobian += x(a) * dN.transpose();
    }
    EXPECT_GT(jacobian.determinant(), 0);
    volume += jacobian.determinant();
  }
  return volume;
}

double meshVolume(const Mesh& mesh) {
  double volume = 0;
  for (const Cell& cell : mesh.cells) {
    const double v = cellVolume(mesh, cell);
    EXPECT_GT(v, 0);
    volume += v;
  }
  return volume;
}

// Area times unit normal by the right-hand rule (for a quad: half the cross product of its diagonals).
Vec3 areaVector(const Mesh& mesh, const Face& face) {
  auto x = [&](int local) { return mesh.nodes[face.nodes[local]]; };
  if (face.count == 3) return (x(1) - x(0)).cross(x(2) - x(0)) / 2;
  return (x(2) - x(0)).cross(x(3) - x(1)) / 2;
}

double totalArea(const Mesh& mesh, const std::vector<Face>& faces) {
  double area = 0;
  for (const Face& face : faces) area += areaVector(mesh, face).norm();
  return area;
}

Vec3 centroid(const Mesh& mesh, const int* nodes, int count) {
  Vec3 sum = Vec3::Zero();
  for (int n = 0; n < count; ++n) sum += mesh.nodes[nodes[n]];
  return sum / count;
}

// Every face's normal points away from the centroid of the cell that holds all its nodes.
void expectOutward(const Mesh& mesh, const std::vector<Face>& faces) {
  for (const Face& face : faces) {
    const auto cell = std::find_if(mesh.cells.begin(), mesh.cells.end(), [&](const Cell& c) {
      const auto end = c.nodes.begin() + nodeCount(c.type);
      return std::all_of(face.nodes.begin(), face.nodes.begin() + face.count,
                         [&](int n) { return std::find(c.nodes.begin(), end, n) != end; });
    });
    ASSERT_NE(cell, mesh.cells.end());
    const Vec3 out =
        centroid(mesh, face.nodes.data(), face.count) - centroid(mesh, cell->nodes.data(), nodeCount(cell->type));
    EXPECT_GT(areaVector(mesh, face).dot(out), 0);
  }
}

// Area vectors of a closed surface sum to zero.
void expectClosed(const Mesh& mesh, const std::vector<Face>& faces) {
  Vec3 sum = Vec3::Zero();
  for (const Face& face : faces) sum += areaVector(mesh, face);
  EXPECT_LT(sum.norm(), 1e-12);
}

TEST(BoxMesh, CountsVolumeAndSurfaces) {
  const Mesh mesh = makeBoxMesh(Vec3(1, 2, 3), Vec3(2, 3, 4), {2, 3, 4});
  EXPECT_EQ(mesh.nodes.size(), 3u * 4 * 5);
  EXPECT_EQ(mesh.cells.size(), 2u * 3 * 4);
  EXPECT_EQ(mesh.volumes.at("all").size(), 24u);
  EXPECT_NEAR(meshVolume(mesh), 24.0, 1e-12);
  const std::vector<Face> boundary = mesh.boundaryFaces();
  EXPECT_EQ(boundary.size(), 2u * (6 + 8 + 12));
  EXPECT_NEAR(totalArea(mesh, boundary), 2 * (6.0 + 8 + 12), 1e-12);
  expectClosed(mesh, boundary);
  expectOutward(mesh, boundary);
  // each named side: its area, its outward axis direction, its nodes on the plane
  const std::string names[6] = {"x0", "x1", "y0", "y1", "z0", "z1"};
  const double areas[3] = {12, 8, 6};
  for (int side = 0; side < 6; ++side) {
    const int axis = side / 2;
    const std::vector<Face>& faces = mesh.surfaces.at(names[side]);
    EXPECT_NEAR(totalArea(mesh, faces), areas[axis], 1e-12) << names[side];
    for (const Face& face : faces)
      EXPECT_NEAR(areaVector(mesh, face).normalized()[axis], side % 2 ? 1.0 : -1.0, 1e-12) << names[side];
    const double plane = side % 2 ? Vec3(3, 5, 7)[axis] : Vec3(1, 2, 3)[axis];
    for (int node : mesh.nodesOf(names[side])) EXPECT_EQ(mesh.nodes[node][axis], plane);
  }
  EXPECT_EQ(mesh.nodesOf("x0").size(), 4u * 5);
}

TEST(BoxMesh, RejectsBadArgumentsAndUnknownNames) {
  EXPECT_THROW(makeBoxMesh(Vec3::Zero(), Vec3(1, 1, 1), {0, 1, 1}), std::invalid_argument);
  EXPECT_THROW(makeBoxMesh(Vec3::Zero(), Vec3(1, -1, 1), {1, 1, 1}), std::invalid_argument);
  const Mesh mesh = makeBoxMesh(Vec3::Zero(), Vec3(1, 1, 1), {1, 1, 1});
  try {
    mesh.nodesOf("clamp");
    FAIL() << "no exception";
  } catch (const std::out_of_range& error) {
    EXPECT_NE(std::string(error.what()).find("clamp"), std::string::npos);
  }
}

TEST(LBlockMesh, CoarseLevel) {
  const Mesh mesh = makeLBlockMesh(1);
  EXPECT_EQ(mesh.cells.size(), 36u);
  EXPECT_EQ(mesh.nodes.size(), 90u);
  EXPECT_NEAR(meshVolume(mesh), 117.0, 1e-12);
  // each loaded end is a 3 x 3 square in 2 x 2 quads facing out along its axis
  for (const auto& [name, axis] : {std::pair<std::string, int>{"load_y10", 1}, {"load_x6", 0}}) {
    const std::vector<Face>& faces = mesh.surfaces.at(name);
    EXPECT_EQ(faces.size(), 4u) << name;
    EXPECT_NEAR(totalArea(mesh, faces), 9.0, 1e-12) << name;
    for (const Face& face : faces) {
      EXPECT_EQ(face.count, 4);
      EXPECT_NEAR(areaVector(mesh, face).normalized()[axis], 1.0, 1e-12) << name;
    }
    EXPECT_EQ(mesh.nodesOf(name).size(), 9u) << name;
  }
  // the boundary: L-shaped top and bottom (2 x 39) and sides around the perimeter 32, 3 high
  const std::vector<Face>& boundary = mesh.surfaces.at("boundary");
  EXPECT_NEAR(totalArea(mesh, boundary), 2 * 39.0 + 32 * 3, 1e-12);
  expectClosed(mesh, boundary);
  expectOutward(mesh, boundary);
  EXPECT_EQ(mesh.volumes.at("all").size(), 36u);
}

TEST(LBlockMesh, RefinedLevelsMergeNodes) {
  const Mesh level2 = makeLBlockMesh(2);
  EXPECT_EQ(level2.cells.size(), 288u);
  EXPECT_EQ(level2.nodes.size(), 475u);
  EXPECT_NEAR(meshVolume(level2), 117.0, 1e-11);
  EXPECT_EQ(level2.surfaces.at("load_y10").size(), 16u);
  // one node per point: no two nodes closer than the smallest cell edge
  std::vector<Vec3> sorted = level2.nodes;
  std::sort(sorted.begin(), sorted.end(), [](const Vec3& a, const Vec3& b) {
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  });
  for (size_t n = 1; n < sorted.size(); ++n) EXPECT_GT((sorted[n] - sorted[n - 1]).norm(), 0.5);
  EXPECT_EQ(makeLBlockMesh(4).nodes.size(), 2997u);
  const Mesh level7 = makeLBlockMesh(7);
  EXPECT_EQ(level7.nodes.size(), 14400u);
  EXPECT_EQ(level7.cells.size(), 36u * 343);
  EXPECT_THROW(makeLBlockMesh(0), std::invalid_argument);
}

// The 2 x 1 x 1 hex block: the second hex is listed upside down (negative Jacobian), the "left" quad inward.
const char* const kHexBlockNames = R"($PhysicalNames
5
0 5 "corner"
1 6 "bottom edge"
2 1 "left"
2 2 "right"
3 3 "solid"
$EndPhysicalNames
)";

const std::string kHexBlock22 = std::string(R"($MeshFormat
2.2 0 8
$EndMeshFormat
)") + kHexBlockNames + R"($Nodes
12
1 0 0 0
2 1 0 0
3 2 0 0
4 0 1 0
5 1 1 0
6 2 1 0
7 0 0 1
8 1 0 1
9 2 0 1
10 0 1 1
11 1 1 1
12 2 1 1
$EndNodes
$Elements
7
1 15 2 5 1 1
2 1 2 6 1 1 2
3 3 2 1 1 1 4 10 7
4 3 2 2 2 3 6 12 9
5 3 2 7 3 1 2 5 4
6 5 2 3 1 1 2 5 4 7 8 11 10
7 5 2 3 1 8 9 12 11 2 3 6 5
$EndElements
)";

const std::string kHexBlock41 = std::string(R"($MeshFormat
4.1 0 8
$EndMeshFormat
$Comments
free text $ that is skipped
$EndComments
)") + kHexBlockNames + R"($Entities
1 1 3 1
1 0 0 0 1 5
1 0 0 0 1 0 0 1 6 2 1 -2
1 0 0 0 0 1 1 1 1 0
2 2 0 0 2 1 1 1 2 0
3 0 0 0 1 1 0 1 7 0
1 0 0 0 2 1 1 1 3 0
$EndEntities
$Nodes
2 12 1 12
0 1 0 1
1
0 0 0
3 1 0 11
2
3
4
5
6
7
8
9
10
11
12
1 0 0
2 0 0
0 1 0
1 1 0
2 1 0
0 0 1
1 0 1
2 0 1
0 1 1
1 1 1
2 1 1
$EndNodes
$Elements
6 7 1 7
0 1 15 1
1 1
1 1 1 1
2 1 2
2 1 3 1
3 1 4 10 7
2 2 3 1
4 3 6 12 9
2 3 3 1
5 1 2 5 4
3 1 5 2
6 1 2 5 4 7 8 11 10
7 8 9 12 11 2 3 6 5
$EndElements
$Periodic
0
$EndPeriodic
)";

void expectHexBlock(const Mesh& mesh) {
  EXPECT_EQ(mesh.nodes.size(), 12u);
  ASSERT_EQ(mesh.cells.size(), 2u);
  EXPECT_NEAR(meshVolume(mesh), 2.0, 1e-12);
  EXPECT_EQ(mesh.volumes.size(), 1u);
  EXPECT_EQ(mesh.volumes.at("solid"), (std::vector<int>{0, 1}));
  ASSERT_EQ(mesh.surfaces.size(), 3u);
  const Vec3 expectedNormal[3] = {Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, -1)};
  const char* names[3] = {"left", "right", "7"};
  for (int s = 0; s < 3; ++s) {
    const std::vector<Face>& faces = mesh.surfaces.at(names[s]);
    ASSERT_EQ(faces.size(), 1u) << names[s];
    EXPECT_NEAR((areaVector(mesh, faces[0]) - expectedNormal[s]).norm(), 0, 1e-12) << names[s];
    expectOutward(mesh, faces);
  }
  for (int node : mesh.nodesOf("left")) EXPECT_EQ(mesh.nodes[node].x(), 0);
  EXPECT_EQ(mesh.nodesOf("corner").size(), 1u);
  EXPECT_EQ(mesh.nodes[mesh.nodesOf("corner")[0]], Vec3(0, 0, 0));
  EXPECT_EQ(mesh.nodesOf("bottom edge").size(), 2u);
  const std::vector<Face> boundary = mesh.boundaryFaces();
  EXPECT_EQ(boundary.size(), 10u);
  EXPECT_NEAR(totalArea(mesh, boundary), 10.0, 1e-12);
  expectClosed(mesh, boundary);
}

TEST(GmshReader, HexBlockFormat22) {
  const fs::path dir = testDir("hex22");
  expectHexBlock(readGmshMesh(writeFile(dir / "block.msh", kHexBlock22)));
}

TEST(GmshReader, HexBlockFormat41) {
  const fs::path dir = testDir("hex41");
  expectHexBlock(readGmshMesh(writeFile(dir / "block.msh", kHexBlock41)));
}

TEST(GmshReader, SingleTetWithNamedSurfaces) {
  const fs::path dir = testDir("tet");
  // the tet is listed with negative volume; the skin triangles in mixed orientations
  const Mesh mesh = readGmshMesh(writeFile(dir / "tet.msh", R"($MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
3
1 4 "edge"
2 1 "skin"
2 2 "bottom"
$EndPhysicalNames
$Nodes
4
10 0 0 0
20 0 1 0
30 1 0 0
40 0 0 1
$EndNodes
$Elements
7
1 1 2 4 1 10 20
2 2 2 1 1 10 20 30
3 2 2 1 1 10 20 40
4 2 2 1 1 20 30 40
5 2 2 1 1 10 40 30
6 2 2 2 1 10 30 20
7 4 2 0 1 10 20 30 40
$EndElements
)"));
  ASSERT_EQ(mesh.cells.size(), 1u);
  EXPECT_EQ(mesh.cells[0].type, CellType::Tet4);
  EXPECT_NEAR(meshVolume(mesh), 1.0 / 6, 1e-15);
  EXPECT_EQ(mesh.volumes.at("all"), std::vector<int>{0});
  const std::vector<Face>& skin = mesh.surfaces.at("skin");
  ASSERT_EQ(skin.size(), 4u);
  expectClosed(mesh, skin);
  expectOutward(mesh, skin);
  EXPECT_NEAR((areaVector(mesh, mesh.surfaces.at("bottom")[0]) - Vec3(0, 0, -0.5)).norm(), 0, 1e-15);
  EXPECT_EQ(mesh.nodesOf("edge"), (std::vector<int>{0, 1}));
  EXPECT_EQ(mesh.nodesOf("skin"), (std::vector<int>{0, 1, 2, 3}));
}

// A valid one-tet 2.2 file, line by line, for the malformed variants below.
std::vector<std::string> tetLines() {
  return {"$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$Nodes",    "4", "1 0 0 0",           "2 1 0 0",
          "3 0 1 0",     "4 0 0 1", "$EndNodes",      "$Elements", "1", "1 4 2 1 1 1 2 3 4", "$EndElements"};
}

std::string joined(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += line + "\n";
  return text;
}

// The file is rejected with an InputError naming it, the line and (part of) what is wrong.
void expectInputError(const std::string& fileName, const std::string& text, int line, const std::string& what) {
  const std::string path = writeFile(testDir("malformed") / fileName, text);
  try {
    readGmshMesh(path);
    ADD_FAILURE() << fileName << ": no exception";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find(fileName + ":" + std::to_string(line) + ":"), std::string::npos) << message;
    EXPECT_NE(message.find(what), std::string::npos) << message;
  }
}

TEST(GmshReader, ValidTetFixtureReads) {
  const Mesh mesh = readGmshMesh(writeFile(testDir("tet_ok") / "tet.msh", joined(tetLines())));
  EXPECT_EQ(mesh.cells.size(), 1u);
}

TEST(GmshReader, RejectsMalformedFiles) {
  auto with = [](int line, const std::string& text) {
    std::vector<std::string> lines = tetLines();
    lines[line - 1] = text;
    return joined(lines);
  };
  std::vector<std::string> cut = tetLines();
  cut.resize(8);
  expectInputError("truncated_nodes.msh", with(5, "5"), 10, "$Nodes ends before a node tag");
  expectInputError("cut_in_nodes.msh", joined(cut), 8, "the file ends inside $Nodes");
  expectInputError("extra_node.msh", with(5, "3"), 9, "unexpected '4'");
  expectInputError("unknown_node.msh", with(13, "1 4 2 1 1 1 2 3 99"), 13, "unknown node 99");
  expectInputError("version3.msh", with(2, "3.0 0 8"), 2, "unsupported Gmsh format version 3.0");
  expectInputError("binary.msh", with(2, "2.2 1 8"), 2, "binary");
  expectInputError("nan.msh", with(8, "3 nan 1 0"), 8, "not a finite number");
  expectInputError("inf.msh", with(7, "2 1 0 inf"), 7, "not a finite number");
  expectInputError("word.msh", with(7, "2 1 x 0"), 7, "found 'x'");
  expectInputError("tet10.msh", with(13, "1 11 2 1 1 1 2 3 4 1 2 3 4 1 2"), 13,
                   "element type 11 (10-node tetrahedron)");
  expectInputError("no_volume.msh", with(13, "1 2 2 1 1 1 2 3"), 11, "no volume elements");
  expectInputError("flat.msh", with(9, "4 1 1 0"), 13, "zero volume");
  expectInputError("unknown_type.msh", with(13, "1 99 2 1 1 1 2 3 4"), 13, "unknown element type 99");
  std::vector<std::string> noElements = tetLines();
  noElements.resize(10);
  expectInputError("no_elements.msh", joined(noElements), 10, "no $Elements section");
  expectInputError("no_format.msh", joined({"$Nodes", "0", "$EndNodes"}), 1, "must start with $MeshFormat");
  std::vector<std::string> unclosed = tetLines();
  unclosed.erase(unclosed.begin() + 9);
  expectInputError("unclosed.msh", joined(unclosed), 10, "expected $EndNodes");
}

TEST(GmshReader, RejectsMalformedFormat41) {
  const std::string header = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  // nodes block announces 2 nodes, the header 3
  expectInputError("count41.msh", header + "$Nodes\n1 3 1 3\n3 1 0 2\n1\n2\n0 0 0\n1 0 0\n$EndNodes\n", 5,
                   "announces 3 nodes");
  // a node with an infinite coordinate in the coordinate lines after the tags
  expectInputError("inf41.msh", header + "$Nodes\n1 1 1 1\n3 1 0 1\n1\n0 -inf 0\n$EndNodes\n", 8,
                   "not a finite number");
  // an element block of an entity missing from $Entities
  expectInputError("entity41.msh",
                   header +
                       "$Entities\n0 0 0 0\n$EndEntities\n$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n"
                       "0 1 0\n0 0 1\n$EndNodes\n$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n",
                   21, "unknown entity 1");
}

TEST(GmshReader, MissingFileIsAnInputError) {
  EXPECT_THROW(readGmshMesh((testDir("missing") / "none.msh").string()), InputError);
}

// Parsed XML of a written file, failing the test if it does not parse.
void expectParses(tinyxml2::XMLDocument& document, const fs::path& path) {
  ASSERT_EQ(document.LoadFile(path.c_str()), tinyxml2::XML_SUCCESS) << path;
  EXPECT_FALSE(fs::exists(path.string() + ".part"));
}

TEST(VtkWriter, WritesUnstructuredGridAndCollection) {
  const fs::path dir = testDir("vtk");
  const Mesh mesh = makeBoxMesh(Vec3::Zero(), Vec3(1, 1, 1), {2, 1, 1});
  std::vector<Vec3> positions = mesh.nodes;
  std::vector<double> displacement(3 * positions.size(), 0.25);
  for (Vec3& x : positions) x += Vec3::Constant(0.25);
  writeVtu((dir / "frame_0.vtu").string(), mesh, positions, {{"displacement", 3, displacement}},
           {{"stress <xx>", 1, {1.5, -2.5}}});
  tinyxml2::XMLDocument vtu;
  expectParses(vtu, dir / "frame_0.vtu");
  const tinyxml2::XMLElement* piece =
      vtu.RootElement()->FirstChildElement("UnstructuredGrid")->FirstChildElement("Piece");
  ASSERT_NE(piece, nullptr);
  EXPECT_EQ(piece->IntAttribute("NumberOfPoints"), 12);
  EXPECT_EQ(piece->IntAttribute("NumberOfCells"), 2);
  const tinyxml2::XMLElement* cellField = piece->FirstChildElement("CellData")->FirstChildElement("DataArray");
  EXPECT_STREQ(cellField->Attribute("Name"), "stress <xx>");
  const tinyxml2::XMLElement* types = piece->FirstChildElement("Cells")->LastChildElement("DataArray");
  EXPECT_STREQ(types->Attribute("Name"), "types");
  std::istringstream typeValues(types->GetText());
  EXPECT_EQ(std::vector<int>(std::istream_iterator<int>(typeValues), {}), (std::vector<int>{12, 12}));

  PvdSeries series((dir / "run.pvd").string());
  series.add(0.0, "frame_0.vtu");
  series.write();
  series.add(0.5, "frame_1.vtu");
  series.write();
  tinyxml2::XMLDocument pvd;
  expectParses(pvd, dir / "run.pvd");
  const tinyxml2::XMLElement* second = pvd.RootElement()->FirstChildElement("Collection")->LastChildElement("DataSet");
  EXPECT_DOUBLE_EQ(second->DoubleAttribute("timestep"), 0.5);
  EXPECT_STREQ(second->Attribute("file"), "frame_1.vtu");
}

TEST(VtkWriter, TetCellTypeAndErrors) {
  const fs::path dir = testDir("vtk_tet");
  Mesh mesh;
  mesh.nodes = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  mesh.cells = {{CellType::Tet4, {0, 1, 2, 3}}};
  writeVtu((dir / "tet.vtu").string(), mesh, mesh.nodes, {}, {});
  tinyxml2::XMLDocument vtu;
  expectParses(vtu, dir / "tet.vtu");
  const tinyxml2::XMLElement* cells =
      vtu.RootElement()->FirstChildElement("UnstructuredGrid")->FirstChildElement("Piece")->FirstChildElement("Cells");
  EXPECT_EQ(std::stoi(cells->LastChildElement("DataArray")->GetText()), 10);
  EXPECT_THROW(writeVtu((dir / "bad.vtu").string(), mesh, mesh.nodes, {{"u", 3, {1, 2}}}, {}), std::invalid_argument);
  const std::string unwritable = (dir / "no_such_dir" / "x.vtu").string();
  try {
    writeVtu(unwritable, mesh, mesh.nodes, {}, {});
    FAIL() << "no exception";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find(unwritable), std::string::npos);
  }
}

TEST(SurfaceRender, LBlockPng) {
  const fs::path dir = testDir("render");
  const Mesh mesh = makeLBlockMesh(2);
  std::vector<double> height;
  for (const Cell& cell : mesh.cells) height.push_back(centroid(mesh, cell.nodes.data(), 8).y());
  const fs::path png = dir / "lblock_level2.png";
  renderSurfacePng(png.string(), mesh, mesh.nodes, height, "y of the cell centre", "L-block, level 2");
  std::ifstream file(png, std::ios::binary);
  std::string signature(8, '\0');
  file.read(signature.data(), 8);
  EXPECT_EQ(signature, "\x89PNG\r\n\x1a\n");
  EXPECT_GT(fs::file_size(png), 10000u);
  EXPECT_FALSE(fs::exists(png.string() + ".render"));
}

}  // namespace
}  // namespace mpx::test
