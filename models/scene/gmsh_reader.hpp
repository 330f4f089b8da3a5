#pragma once
// Reading Gmsh ASCII meshes (.msh, formats 2.2 and 4.1) into a Mesh with named volumes, surfaces and node sets.
#include "models/fe/mesh.hpp"

#include <string>

namespace mpx {

// Reads a Gmsh ASCII mesh, format 2.2 or 4.1 ($MeshFormat decides). Volume elements: 4-node tetrahedra (type 4) and
// 8-node hexahedra (type 5); other volume types (e.g. 10-node tets, type 11) are an error naming the type. Surface
// elements (tri3 type 2, quad4 type 3) in physical surfaces become named face sets (oriented outward with respect to
// the adjacent cell); points/lines in physical groups become node sets; volume elements in physical volumes become
// named volumes. Names come from $PhysicalNames; a group without a name is called by its tag as a string ("7"). If the
// file has volume elements but no physical volume, all cells form volume "all". Nodes are renumbered compactly
// 0..N-1; unused nodes (e.g. geometry points) may remain. Cells with a negative Jacobian are reordered so that every
// cell has positive volume.
// Any malformed input (missing section, bad count, non-numeric token, unknown node tag, binary format, unsupported
// version, NaN/inf coordinates, a file without volume elements) throws mpx::InputError(file, line, message) with the
// 1-based line number where the problem is, and a message saying what is wrong.
Mesh readGmshMesh(const std::string& path);

}  // namespace mpx
