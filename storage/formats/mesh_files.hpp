// Meshes for the tools clothing staff and CAD users open: Wavefront OBJ and binary
// STL, in millimetres with Y up (the scan's own frame). PLY is in recon/io.
#pragma once

#include <string>

#include "recon/core/status.hpp"
#include "recon/geometry/triangle_mesh.hpp"

namespace bodyscan::storage {

// OBJ: `v x y z`, `vn` when the mesh has normals, and `f` with 1-based indices.
std::string encode_obj(const TriangleMesh& mesh);
// Binary STL: an 80-byte header, the triangle count, and per triangle its unit
// normal (from its corners) and corners, float32 little-endian.
std::string encode_stl(const TriangleMesh& mesh);

// Written whole or not at all (recon/io/atomic_file.hpp).
Status write_obj(const std::string& path, const TriangleMesh& mesh);
Status write_stl(const std::string& path, const TriangleMesh& mesh);

}  // namespace bodyscan::storage
