// An indexed triangle mesh. Triangles wind counter-clockwise seen from outside.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "recon/geometry/point_cloud.hpp"

namespace bodyscan {

using Triangle = std::array<uint32_t, 3>;

struct TriangleMesh {
  // mm, world frame.
  std::vector<Vec3f> vertices;
  std::vector<Triangle> triangles;
  // Optional unit vertex normals (outward). Empty if not known.
  std::vector<Vec3f> normals;
  // Optional per-vertex confidence in [0, 1]: 1 where the surface rests on
  // measured points, 0 where it was invented to close a hole (fill_holes.hpp).
  // Empty if not known. Measurements flag loops that cross low-confidence parts.
  std::vector<float> confidence;

  size_t num_vertices() const { return vertices.size(); }
  size_t num_triangles() const { return triangles.size(); }
  bool empty() const { return triangles.empty(); }

  // True when every index is in range and normals and confidence are absent or
  // one per vertex.
  bool is_consistent() const;
};

// Topology summary used by tests and reports.
struct MeshTopology {
  size_t boundary_edges = 0;        // edges used by exactly one triangle
  size_t non_manifold_edges = 0;    // edges used by more than two triangles
  size_t inconsistent_edges = 0;    // interior edges whose two triangles disagree on winding
  size_t degenerate_triangles = 0;  // repeated index
  size_t unreferenced_vertices = 0;
  size_t components = 0;          // connected by shared edges
  long euler_characteristic = 0;  // V - E + F over referenced vertices
  bool closed() const { return boundary_edges == 0 && non_manifold_edges == 0; }
};

MeshTopology analyze_topology(const TriangleMesh& mesh);

// Area-weighted outward vertex normals from the triangles.
std::vector<Vec3f> compute_vertex_normals(const TriangleMesh& mesh);

// Signed volume (mm^3) of a closed mesh; positive when triangles wind outward.
double signed_volume(const TriangleMesh& mesh);
double surface_area(const TriangleMesh& mesh);

}  // namespace bodyscan
