#include "models/scene/gmsh_reader.hpp"

#include "engine/core/input_error.hpp"
#include "models/scene/input_file.hpp"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <numeric>
#include <sstream>
#include <unordered_map>

namespace mpx {

namespace {

// A word of the file in a message: its first 40 bytes.
std::string shown(const std::string& text) { return text.size() > 40 ? text.substr(0, 40) + "..." : text; }

// What Gmsh element types are: nodes per element and dimension (the first- and second-order types 1..19).
struct ElementKind {
  int nodes;
  int dimension;
  const char* name;
};

const ElementKind* elementKind(long long type) {
  static const std::map<long long, ElementKind> kinds = {
      {1, {2, 1, "2-node line"}},        {2, {3, 2, "3-node triangle"}},       {3, {4, 2, "4-node quadrangle"}},
      {4, {4, 3, "4-node tetrahedron"}}, {5, {8, 3, "8-node hexahedron"}},     {6, {6, 3, "6-node prism"}},
      {7, {5, 3, "5-node pyramid"}},     {8, {3, 1, "3-node line"}},           {9, {6, 2, "6-node triangle"}},
      {10, {9, 2, "9-node quadrangle"}}, {11, {10, 3, "10-node tetrahedron"}}, {12, {27, 3, "27-node hexahedron"}},
      {13, {18, 3, "18-node prism"}},    {14, {14, 3, "14-node pyramid"}},     {15, {1, 0, "point"}},
      {16, {8, 2, "8-node quadrangle"}}, {17, {20, 3, "20-node hexahedron"}},  {18, {15, 3, "15-node prism"}},
      {19, {13, 3, "13-node pyramid"}}};
  auto kind = kinds.find(type);
  return kind == kinds.end() ? nullptr : &kind->second;
}

constexpr int kTet4 = 4, kHex8 = 5, kTri3 = 2, kQuad4 = 3;

// A word of the file and the line it is on.
struct Token {
  std::string text;
  int line;
};

// Splits lines into words; a "quoted string" is one word, since physical names may hold spaces.
std::vector<Token> tokenize(const std::vector<std::string>& lines, int begin, int end) {
  std::vector<Token> tokens;
  for (int l = begin; l < end; ++l) {
    const std::string& text = lines[l];
    size_t pos = 0;
    while (true) {
      pos = text.find_first_not_of(" \t\r", pos);
      if (pos == std::string::npos) break;
      size_t stop = text[pos] == '"' ? text.find('"', pos + 1) : text.find_first_of(" \t\r", pos);
      if (text[pos] == '"' && stop != std::string::npos) ++stop;
      stop = std::min(stop, text.size());
      tokens.push_back({text.substr(pos, stop - pos), l + 1});
      pos = stop;
    }
  }
  return tokens;
}

// The words between a section's header and its $End line, read one at a time. Every read names what it expects, so
// that a message can say what is wrong and on which line.
class SectionReader {
 public:
  SectionReader(std::string file, std::string name, std::vector<Token> tokens, int endLine)
      : file_(std::move(file)), name_(std::move(name)), tokens_(std::move(tokens)), endLine_(endLine) {}

  const std::string& name() const { return name_; }
  // line and text of the word read last
  int line() const { return position_ == 0 ? endLine_ : tokens_[position_ - 1].line; }
  const std::string& lastText() const { return tokens_[position_ - 1].text; }

  const Token& next(const std::string& what) {
    if (position_ == tokens_.size())
      fail(endLine_, "$" + name_ + " ends before " + what + " (a count is too large or data is missing)");
    return tokens_[position_++];
  }

  long long integer(const std::string& what) {
    const Token& token = next(what);
    errno = 0;
    char* end = nullptr;
    const long long value = std::strtoll(token.text.c_str(), &end, 10);
    if (*end || errno) fail(token.line, "expected " + what + " (an integer), found '" + shown(token.text) + "'");
    return value;
  }

  int count(const std::string& what) {
    const long long value = integer(what);
    if (value < 0 || value > INT_MAX) fail(line(), what + " " + std::to_string(value) + " is out of range");
    return static_cast<int>(value);
  }

  double real(const std::string& what) {
    const Token& token = next(what);
    char* end = nullptr;
    const double value = std::strtod(token.text.c_str(), &end);
    if (*end) fail(token.line, "expected " + what + " (a number), found '" + shown(token.text) + "'");
    if (!std::isfinite(value)) fail(token.line, what + " is '" + shown(token.text) + "', not a finite number");
    return value;
  }

  std::string quoted(const std::string& what) {
    const Token& token = next(what);
    if (token.text.size() < 2 || token.text.front() != '"' || token.text.back() != '"')
      fail(token.line, "expected " + what + " in double quotes, found '" + shown(token.text) + "'");
    return token.text.substr(1, token.text.size() - 2);
  }

  // All words must have been read: extra data means a count in the section is too small.
  void finish() const {
    if (position_ < tokens_.size())
      fail(tokens_[position_].line, "unexpected '" + shown(tokens_[position_].text) + "' before $End" + name_ +
                                        " (a count is too small or there is extra data)");
  }

  [[noreturn]] void fail(int line, const std::string& message) const {
    throw InputError(file_, line, printable(message));
  }

 private:
  std::string file_, name_;
  std::vector<Token> tokens_;
  int endLine_;
  size_t position_ = 0;
};

// An element as read, before it becomes a cell, a face or node-set members.
struct GmshElement {
  long long tag;
  long long type;
  int dimension;
  std::vector<int> nodes;  // compact node indices
  std::vector<int> physicals;
  int line;
};

// Signed measure of a cell: six times the volume of a tet, the Jacobian determinant at the centre of a hex.
double orientation(const Cell& cell, const std::vector<Vec3>& nodes) {
  auto x = [&](int local) { return nodes[cell.nodes[local]]; };
  if (cell.type == CellType::Tet4) return (x(1) - x(0)).cross(x(2) - x(0)).dot(x(3) - x(0));
  const Vec3 dXi = x(1) + x(2) + x(5) + x(6) - x(0) - x(3) - x(4) - x(7);
  const Vec3 dEta = x(2) + x(3) + x(6) + x(7) - x(0) - x(1) - x(4) - x(5);
  const Vec3 dZeta = x(4) + x(5) + x(6) + x(7) - x(0) - x(1) - x(2) - x(3);
  return dXi.cross(dEta).dot(dZeta);
}

// Turns a cell of negative volume inside out: a mirrored tet swaps two nodes, a mirrored hex swaps bottom and top.
void reverse(Cell& cell) {
  if (cell.type == CellType::Tet4) {
    std::swap(cell.nodes[1], cell.nodes[2]);
  } else {
    std::swap_ranges(cell.nodes.begin(), cell.nodes.begin() + 4, cell.nodes.begin() + 4);
  }
}

class GmshParser {
 public:
  GmshParser(std::string path, std::vector<std::string> lines) : path_(std::move(path)), lines_(std::move(lines)) {}

  Mesh parse() {
    const int lineCount = static_cast<int>(lines_.size());
    for (int l = 0; l < lineCount; ++l) {
      const std::string header = trimmed(lines_[l]);
      if (header.empty()) continue;
      if (header[0] != '$') fail(l + 1, "expected a section header such as $Nodes, found '" + shown(header) + "'");
      const std::string name = header.substr(1);
      if (version_ == 0 && name != "MeshFormat") fail(l + 1, "the file must start with $MeshFormat, found " + header);
      const int end = sectionEnd(name, l);
      // sections this reader does not need, such as $Periodic or $NodeData, are skipped unread
      if (isReadSection(name)) {
        SectionReader body(path_, name, tokenize(lines_, l + 1, end), end + 1);
        readSection(body, l + 1);
      }
      l = end;
    }
    if (version_ == 0) fail(1, "no $MeshFormat section: this is not a Gmsh mesh");
    if (!nodesLine_) fail(std::max(lineCount, 1), "the file has no $Nodes section");
    if (!elementsLine_) fail(std::max(lineCount, 1), "the file has no $Elements section");
    return buildMesh();
  }

 private:
  [[noreturn]] void fail(int line, const std::string& message) const {
    throw InputError(path_, line, printable(message));
  }

  static std::string trimmed(const std::string& text) {
    const size_t first = text.find_first_not_of(" \t\r");
    if (first == std::string::npos) return "";
    return text.substr(first, text.find_last_not_of(" \t\r") - first + 1);
  }

  static bool isReadSection(const std::string& name) {
    return name == "MeshFormat" || name == "PhysicalNames" || name == "Entities" || name == "Nodes" ||
           name == "Elements";
  }

  // Index of the $End line of the section opened at line index `begin`. Sections read may not hold other headers, so
  // a missing $End is reported where the next section starts; other sections are skipped as opaque text.
  int sectionEnd(const std::string& name, int begin) const {
    const bool known = isReadSection(name);
    for (int l = begin + 1; l < static_cast<int>(lines_.size()); ++l) {
      const std::string text = trimmed(lines_[l]);
      if (text == "$End" + name) return l;
      if (known && !text.empty() && text[0] == '$')
        fail(l + 1, "$" + name + " (line " + std::to_string(begin + 1) + ") is not closed: expected $End" + name +
                        ", found " + text);
    }
    fail(std::max(static_cast<int>(lines_.size()), 1),
         "the file ends inside $" + name + " (line " + std::to_string(begin + 1) + "): no $End" + name);
  }

  void readSection(SectionReader& body, int headerLine) {
    const std::string& name = body.name();
    if (name == "MeshFormat") {
      readMeshFormat(body, headerLine);
    } else if (name == "PhysicalNames") {
      readPhysicalNames(body);
    } else if (name == "Entities") {
      readEntities(body);
    } else if (name == "Nodes") {
      if (nodesLine_) fail(headerLine, "a second $Nodes section");
      nodesLine_ = headerLine;
      if (version_ == 4.1) {
        readNodes41(body);
      } else {
        readNodes22(body);
      }
    } else if (name == "Elements") {
      if (!nodesLine_) fail(headerLine, "$Elements comes before $Nodes");
      if (elementsLine_) fail(headerLine, "a second $Elements section");
      elementsLine_ = headerLine;
      if (version_ == 4.1) {
        readElements41(body);
      } else {
        readElements22(body);
      }
    }
    body.finish();
  }

  void readMeshFormat(SectionReader& body, int headerLine) {
    if (version_ != 0) fail(headerLine, "a second $MeshFormat section");
    const double version = body.real("the format version");
    if (version != 2.2 && version != 4.1)
      body.fail(body.line(), "unsupported Gmsh format version " + body.lastText() + ": only 2.2 and 4.1 are read");
    if (body.integer("the file type (0 for ASCII)") != 0)
      body.fail(body.line(), "binary Gmsh files are not supported: save the mesh in ASCII");
    body.integer("the data size");
    version_ = version;
  }

  void readPhysicalNames(SectionReader& body) {
    const int count = body.count("the number of physical names");
    for (int n = 0; n < count; ++n) {
      const int dimension = static_cast<int>(body.integer("the dimension of a physical group"));
      const int tag = static_cast<int>(body.integer("the tag of a physical group"));
      names_[{dimension, tag}] = body.quoted("the name of a physical group");
    }
  }

  // $Entities (4.1): the physical groups of every point, curve, surface and volume entity.
  void readEntities(SectionReader& body) {
    int counts[4];
    for (int& count : counts) count = body.count("the number of entities");
    for (int dimension = 0; dimension < 4; ++dimension)
      for (int e = 0; e < counts[dimension]; ++e) {
        const long long tag = body.integer("an entity tag");
        for (int c = 0; c < (dimension == 0 ? 3 : 6); ++c) body.real("an entity bounding-box coordinate");
        std::vector<int>& physicals = entityPhysicals_[{dimension, tag}];
        const int physicalCount = body.count("the number of physical tags");
        for (int p = 0; p < physicalCount; ++p) physicals.push_back(static_cast<int>(body.integer("a physical tag")));
        if (dimension == 0) continue;
        const int boundingCount = body.count("the number of bounding entities");
        for (int b = 0; b < boundingCount; ++b) body.integer("a bounding entity tag");
      }
    hasEntities_ = true;
  }

  void addNode(SectionReader& body, long long tag, int tagLine) {
    if (!nodeIndex_.emplace(tag, static_cast<int>(nodes_.size())).second)
      body.fail(tagLine, "node " + std::to_string(tag) + " is defined twice");
    const std::string of = " of node " + std::to_string(tag);
    const double x = body.real("the x coordinate" + of), y = body.real("the y coordinate" + of);
    nodes_.emplace_back(x, y, body.real("the z coordinate" + of));
  }

  void readNodes22(SectionReader& body) {
    const int count = body.count("the number of nodes");
    for (int n = 0; n < count; ++n) {
      const long long tag = body.integer("a node tag");
      addNode(body, tag, body.line());
    }
  }

  // 4.1 node blocks: a header per entity, then the block's tags, then their coordinates.
  void readNodes41(SectionReader& body) {
    const int blocks = body.count("the number of node blocks");
    const int total = body.count("the number of nodes");
    const int headerLine = body.line();
    body.integer("the smallest node tag");
    body.integer("the largest node tag");
    for (int b = 0; b < blocks; ++b) {
      const long long dimension = body.integer("the dimension of a node block");
      body.integer("the entity tag of a node block");
      const long long parametric = body.integer("the parametric flag of a node block");
      if (dimension < 0 || dimension > 3 || (parametric != 0 && parametric != 1))
        body.fail(body.line(), "invalid node block header (dimension 0..3, parametric 0 or 1)");
      const int size = body.count("the number of nodes in a block");
      std::vector<std::pair<long long, int>> tags;
      for (int n = 0; n < size; ++n) {
        const long long tag = body.integer("a node tag");
        tags.emplace_back(tag, body.line());
      }
      for (const auto& [tag, line] : tags) {
        addNode(body, tag, line);
        for (int p = 0; p < parametric * dimension; ++p) body.real("a parametric coordinate");
      }
    }
    if (static_cast<int>(nodes_.size()) != total)
      body.fail(headerLine, "$Nodes announces " + std::to_string(total) + " nodes but its blocks hold " +
                                std::to_string(nodes_.size()));
  }

  const ElementKind& kindOf(SectionReader& body, long long type) {
    const ElementKind* kind = elementKind(type);
    if (!kind) body.fail(body.line(), "unknown element type " + std::to_string(type));
    if (kind->dimension == 3 && type != kTet4 && type != kHex8)
      body.fail(body.line(), "unsupported volume element type " + std::to_string(type) + " (" + kind->name +
                                 "): only 4-node tetrahedra (type 4) and 8-node hexahedra (type 5) are read");
    return *kind;
  }

  // Reads the node tags of one element as compact node indices.
  std::vector<int> elementNodes(SectionReader& body, long long tag, const ElementKind& kind) {
    std::vector<int> nodes;
    for (int n = 0; n < kind.nodes; ++n) {
      const long long node = body.integer("a node tag of element " + std::to_string(tag));
      auto index = nodeIndex_.find(node);
      if (index == nodeIndex_.end())
        body.fail(body.line(), "element " + std::to_string(tag) + " refers to unknown node " + std::to_string(node));
      nodes.push_back(index->second);
    }
    return nodes;
  }

  // 2.2 elements: tag, type, number of tags, tags (the first is the physical group, 0 for none), node tags.
  void readElements22(SectionReader& body) {
    const int count = body.count("the number of elements");
    for (int e = 0; e < count; ++e) {
      const long long tag = body.integer("an element tag");
      const int line = body.line();
      const long long type = body.integer("the type of element " + std::to_string(tag));
      const ElementKind& kind = kindOf(body, type);
      const int tagCount = body.count("the number of tags of element " + std::to_string(tag));
      std::vector<int> physicals;
      for (int t = 0; t < tagCount; ++t) {
        const long long value = body.integer("a tag of element " + std::to_string(tag));
        if (t == 0 && value != 0) physicals.push_back(static_cast<int>(value));
      }
      elements_.push_back({tag, type, kind.dimension, elementNodes(body, tag, kind), physicals, line});
    }
  }

  // 4.1 element blocks: a header per entity and type, then one line per element (tag, node tags).
  void readElements41(SectionReader& body) {
    const int blocks = body.count("the number of element blocks");
    const int total = body.count("the number of elements");
    const int headerLine = body.line();
    body.integer("the smallest element tag");
    body.integer("the largest element tag");
    for (int b = 0; b < blocks; ++b) {
      const long long dimension = body.integer("the dimension of an element block");
      const long long entity = body.integer("the entity tag of an element block");
      const long long type = body.integer("the element type of a block");
      const ElementKind& kind = kindOf(body, type);
      if (kind.dimension != dimension)
        body.fail(body.line(), std::string("a block of dimension ") + std::to_string(dimension) + " holds " +
                                   kind.name + " elements");
      const std::vector<int> physicals = entityPhysicals(body, kind.dimension, entity);
      const int size = body.count("the number of elements in a block");
      for (int e = 0; e < size; ++e) {
        const long long tag = body.integer("an element tag");
        const int line = body.line();
        elements_.push_back({tag, type, kind.dimension, elementNodes(body, tag, kind), physicals, line});
      }
    }
    if (static_cast<int>(elements_.size()) != total)
      body.fail(headerLine, "$Elements announces " + std::to_string(total) + " elements but its blocks hold " +
                                std::to_string(elements_.size()));
  }

  std::vector<int> entityPhysicals(SectionReader& body, int dimension, long long entity) const {
    if (!hasEntities_) return {};
    auto physicals = entityPhysicals_.find({dimension, entity});
    if (physicals == entityPhysicals_.end())
      body.fail(body.line(), "element block of unknown entity " + std::to_string(entity) + " (dimension " +
                                 std::to_string(dimension) + ")");
    return physicals->second;
  }

  std::string groupName(int dimension, int tag) const {
    auto name = names_.find({dimension, tag});
    return name == names_.end() ? std::to_string(tag) : name->second;
  }

  Cell makeCell(const GmshElement& element) const {
    Cell cell{element.type == kTet4 ? CellType::Tet4 : CellType::Hex8, {}};
    cell.nodes.fill(-1);
    std::copy(element.nodes.begin(), element.nodes.end(), cell.nodes.begin());
    if (orientation(cell, nodes_) < 0) reverse(cell);
    // a flat or tangled cell has no usable orientation; measure it against its size
    double size = 0;
    for (int a = 1; a < nodeCount(cell.type); ++a)
      size = std::max(size, (nodes_[cell.nodes[a]] - nodes_[cell.nodes[0]]).norm());
    if (!(orientation(cell, nodes_) > 1e-12 * size * size * size))
      fail(element.line, "element " + std::to_string(element.tag) + " has zero volume");
    return cell;
  }

  // Named face of a physical surface, in the orientation of the cell it belongs to.
  Face orientedFace(const GmshElement& element, const std::map<std::array<int, 4>, Face>& cellFaceOf,
                    const std::string& group) const {
    if (element.type != kTri3 && element.type != kQuad4)
      fail(element.line, "element " + std::to_string(element.tag) + " of physical surface '" + group + "' is a " +
                             elementKind(element.type)->name +
                             ": only 3-node triangles and 4-node quadrangles are read");
    Face face{static_cast<int>(element.nodes.size()), {-1, -1, -1, -1}};
    std::copy(element.nodes.begin(), element.nodes.end(), face.nodes.begin());
    auto cellFace = cellFaceOf.find(faceKey(face));
    if (cellFace == cellFaceOf.end())
      fail(element.line, "element " + std::to_string(element.tag) + " of physical surface '" + group +
                             "' is not a face of any volume element");
    return cellFace->second;
  }

  Mesh buildMesh() const {
    Mesh mesh;
    mesh.nodes = nodes_;
    // cells first: faces take their orientation from them; an element listed in several groups is one cell
    std::map<long long, int> cellOfTag;
    for (const GmshElement& element : elements_) {
      if (element.dimension != 3) continue;
      auto [cell, added] = cellOfTag.emplace(element.tag, static_cast<int>(mesh.cells.size()));
      if (added) mesh.cells.push_back(makeCell(element));
      for (int physical : element.physicals) mesh.volumes[groupName(3, physical)].push_back(cell->second);
    }
    if (mesh.cells.empty())
      fail(elementsLine_,
           "the mesh has no volume elements (4-node tetrahedra or 8-node hexahedra); with physical "
           "groups defined, Gmsh saves only their elements: add a Physical Volume or set "
           "Mesh.SaveAll=1");
    if (mesh.volumes.empty()) {
      mesh.volumes["all"].resize(mesh.cells.size());
      std::iota(mesh.volumes["all"].begin(), mesh.volumes["all"].end(), 0);
    }
    std::map<std::array<int, 4>, Face> cellFaceOf;
    for (const Cell& cell : mesh.cells)
      for (const Face& face : cellFaces(cell)) cellFaceOf.emplace(faceKey(face), face);
    for (const GmshElement& element : elements_)
      for (int physical : element.physicals) {
        const std::string group = groupName(element.dimension, physical);
        if (element.dimension == 2) {
          mesh.surfaces[group].push_back(orientedFace(element, cellFaceOf, group));
        } else if (element.dimension < 2) {
          mesh.nodeSets[group].insert(mesh.nodeSets[group].end(), element.nodes.begin(), element.nodes.end());
        }
      }
    for (auto* sets : {&mesh.volumes, &mesh.nodeSets})
      for (auto& [name, members] : *sets) {
        std::sort(members.begin(), members.end());
        members.erase(std::unique(members.begin(), members.end()), members.end());
      }
    return mesh;
  }

  std::string path_;
  std::vector<std::string> lines_;
  double version_ = 0;                                // 0 until $MeshFormat is read
  int nodesLine_ = 0, elementsLine_ = 0;              // header lines of $Nodes and $Elements, 0 while not seen
  std::map<std::pair<int, int>, std::string> names_;  // (dimension, physical tag) -> name
  bool hasEntities_ = false;
  std::map<std::pair<int, long long>, std::vector<int>> entityPhysicals_;  // (dimension, entity tag) -> physical tags
  std::unordered_map<long long, int> nodeIndex_;                           // Gmsh node tag -> compact index
  std::vector<Vec3> nodes_;
  std::vector<GmshElement> elements_;
};

}  // namespace

Mesh readGmshMesh(const std::string& path) {
  std::istringstream file(readInputFile(path, "Gmsh mesh file"));
  std::vector<std::string> lines;
  for (std::string line; std::getline(file, line);) lines.push_back(line);
  return GmshParser(path, std::move(lines)).parse();
}

}  // namespace mpx
