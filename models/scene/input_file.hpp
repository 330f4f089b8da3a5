#pragma once
// Reading the files a scene names (the scene itself, URDFs, Gmsh meshes). Only regular files
// are read: a scene that names a device, a FIFO or a directory (`/dev/zero`, `/dev/stdin`)
// would otherwise hang or exhaust memory instead of failing.
#include <string>

namespace mpx {

// The whole text of `path`; throws InputError naming the path and `what` ("scene file",
// "URDF file", "Gmsh mesh file") when it is missing, not a regular file or unreadable.
std::string readInputFile(const std::string& path, const char* what);

}  // namespace mpx
