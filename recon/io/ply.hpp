// PLY (Stanford polygon file format) reading and writing, ASCII and binary
// (little- and big-endian), for point clouds and triangle meshes.
//
// Reading accepts any element/property layout a real-world file may carry: the
// `vertex` element's x,y,z (float or double or any integer type) are required;
// nx,ny,nz, intensity, confidence, camera, laser, frame are picked up when present;
// other properties and elements are skipped. Faces come from the `face` element's
// `vertex_indices` (or `vertex_index`) list; polygons with more than three corners
// are fan-triangulated. An optional `camera` element with x,y,z gives the camera
// centres that the per-vertex `camera` ids index.
//
// Every read is bounded by the bytes actually present: a truncated file, a header
// that lies about its counts, an index out of range, a list length that cannot fit,
// or garbage gives an InvalidArgument Status naming the file position, never a
// crash, a hang or an allocation the file's size cannot justify.
#pragma once

#include <string>
#include <string_view>

#include "core/status.hpp"
#include "recon/geometry/point_cloud.hpp"
#include "recon/geometry/triangle_mesh.hpp"

namespace bodyscan {

enum class PlyFormat { kBinaryLittleEndian, kAscii };

struct PlyData {
  PointCloud cloud;                 // vertex positions and whatever attributes the file has
  std::vector<Triangle> triangles;  // empty for a point cloud
};

// Parses a whole PLY file held in memory. `name` only labels error messages.
StatusOr<PlyData> parse_ply(std::string_view bytes, const std::string& name = "<memory>");

// Reads a PLY file from disk (points, and triangles if it has faces).
StatusOr<PlyData> read_ply(const std::string& path);

// Reads a PLY file that must contain faces, as a mesh (vertex normals kept if present).
StatusOr<TriangleMesh> read_ply_mesh(const std::string& path);

// Writes every present attribute of the cloud (and a `camera` element when the
// cloud has camera centres). Writes to a temporary file beside `path`, flushes and
// fsyncs it, then renames it over `path`, so a reader never sees half a file.
Status write_ply(const std::string& path, const PointCloud& cloud, PlyFormat format = PlyFormat::kBinaryLittleEndian);

// Writes vertices (with normals when present) and triangles; same atomicity.
Status write_ply(const std::string& path, const TriangleMesh& mesh, PlyFormat format = PlyFormat::kBinaryLittleEndian);

// The bytes write_ply would write (for tests and in-memory use).
std::string encode_ply(const PointCloud& cloud, PlyFormat format);
std::string encode_ply(const TriangleMesh& mesh, PlyFormat format);

}  // namespace bodyscan
