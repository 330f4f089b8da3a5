#pragma once
// Structured hexahedral meshes built in code: a box and the tumbling L-block benchmark.
#include "models/fe/mesh.hpp"

namespace mpx {

// Box [origin, origin+size] split in cells[0] x cells[1] x cells[2] hexahedra. Surfaces named
// "x0","x1","y0","y1","z0","z1" (faces at min/max of each axis) and "boundary" (all of them),
// volume "all".
Mesh makeBoxMesh(const Vec3& origin, const Vec3& size, const std::array<int, 3>& cells);

// Tumbling L-block of Simo & Tarnow (docs/theory.md section 11.3): short leg x in [0,6], y in [0,3], z in [0,3]; long
// leg x in [0,3], y in [3,10], z in [0,3]. Level 1 is the coarse mesh: the corner block [0,3]^2 x [0,3] in 2x2x2 cells,
// the short leg x in [3,6] in 2 slices of 2x2 cells, the long leg y in [3,10] in 5 slices of 2x2 cells: 36 hexahedra,
// 90 nodes. Level n splits every coarse cell into n x n x n (level 2: 288 cells, 475 nodes; level 4: 2997 nodes; level
// 7: 14400 nodes). Surfaces: "load_y10" (face y = 10), "load_x6" (face x = 6), plus the full boundary as "boundary";
// volume "all". Shared nodes are merged (one node per point).
Mesh makeLBlockMesh(int level);  // level >= 1, else std::invalid_argument

}  // namespace mpx
