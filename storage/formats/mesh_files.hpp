// Meshes for the tools clothing staff and CAD users open: Wavefront OBJ, binary STL
// and a plain (uncompressed) glTF binary, Y up (the scan's own frame). PLY is in
// recon/io; the Draco-compressed GLB for the browser in draco_files.hpp.
#pragma once

#include <string>

#include "core/status.hpp"
#include "recon/geometry/triangle_mesh.hpp"

namespace bodyscan::storage {

// The unit a file's coordinates are written in (the scan's are millimetres).
enum class ModelUnit { kMillimetre, kMetre };

// OBJ: a comment naming the unit, `v x y z`, `vn` when the mesh has normals, and
// `f` with 1-based indices. OBJ itself has no unit: the importer is told.
std::string encode_obj(const TriangleMesh& mesh, ModelUnit unit = ModelUnit::kMillimetre);
// glTF 2.0 binary with plain accessors (no compression extension, which CAD tools
// seldom read), in metres as glTF defines: float positions with their bounds,
// float normals when the mesh has a unit one per vertex, 32-bit indices, one mesh, one
// node, one grey material. Errors on an empty or inconsistent mesh.
StatusOr<std::string> encode_plain_glb(const TriangleMesh& mesh);
// Binary STL: an 80-byte header, the triangle count, and per triangle its unit
// normal (from its corners) and corners, float32 little-endian.
std::string encode_stl(const TriangleMesh& mesh);

// Written whole or not at all (recon/io/atomic_file.hpp).
Status write_obj(const std::string& path, const TriangleMesh& mesh);
Status write_stl(const std::string& path, const TriangleMesh& mesh);

}  // namespace bodyscan::storage
