// Exact distances from points to a triangle mesh, and the statistics that score a
// reconstruction against its ground truth (tests, benchmarks, accuracy reports).
//
// MeshDistance is a bounding-volume hierarchy (axis-aligned boxes, binned SAH split,
// leaves of at most 4 triangles) answering closest-point queries exactly:
//   closest point on a triangle: C. Ericson, "Real-Time Collision Detection" (2005), §5.1.5;
//   sign of the distance: J. A. Bærentzen, H. Aanæs, "Signed distance computation using
//   the angle weighted pseudonormal", IEEE TVCG 11(3), 2005.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "recon/geometry/point_cloud.hpp"
#include "recon/geometry/triangle_mesh.hpp"

namespace bodyscan {

// ClosestPoint::triangle when the mesh has no triangles.
inline constexpr uint32_t kNoTriangle = std::numeric_limits<uint32_t>::max();

struct ClosestPoint {
  // mm, world frame: the point of the mesh nearest to the query.
  Vec3f point = Vec3f::Zero();
  // mm, |query - point| >= 0; +infinity for a mesh without triangles.
  float distance = std::numeric_limits<float>::infinity();
  // Index into mesh.triangles of a triangle that contains `point` (ties: any one).
  uint32_t triangle = kNoTriangle;
  // mm: +distance outside the surface, -distance inside. The sign comes from the
  // angle-weighted pseudonormal of the nearest feature (face, edge or vertex), which is
  // exact for a closed, edge-manifold mesh wound counter-clockwise seen from outside.
  // On open or non-manifold meshes it is only the side of the nearest feature's
  // averaged normal, and for queries within float rounding of the surface it is noise.
  float signed_distance = std::numeric_limits<float>::infinity();
};

// The point of triangle (a, b, c) nearest p (Ericson §5.1.5).
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c);

class MeshDistance {
 public:
  // Builds the hierarchy in O(T log T) for T triangles and copies what it needs, so
  // `mesh` may change or die afterwards.
  //
  // The mesh's indices must be in range. Degenerate triangles (zero area, or thinner
  // than 1e-7 of their longest edge) are allowed: they behave as their three segments
  // and add nothing to the pseudonormals that give the sign.
  explicit MeshDistance(const TriangleMesh& mesh);

  // The nearest point of the mesh to q (mm, world frame). Thread-safe.
  ClosestPoint closest_point(const Vec3f& q) const;

  // Unsigned distances (mm) from each query to the mesh, computed in parallel;
  // result[i] belongs to queries[i].
  std::vector<float> distances(const std::vector<Vec3f>& queries) const;

  size_t num_triangles() const { return tris_.size(); }
  // Boxes in the hierarchy (1 for a mesh of at most 4 triangles).
  size_t num_nodes() const { return nodes_.size(); }

 private:
  // 32 bytes; the two children of an inner node are adjacent so one cache line holds
  // both boxes the traversal compares.
  struct alignas(32) Node {
    float lo[3];
    uint32_t first;  // inner: index of the first child; leaf: first entry of tris_
    float hi[3];
    uint32_t count;  // 0 for an inner node, else number of triangles in the leaf
  };
  // A triangle as the search loop reads it, in leaf order: corner a and the two edges
  // from a, so that the loop does not gather vertices through indices.
  struct SearchTriangle {
    Vec3f a, ab, ac;
    uint32_t id;  // index into the mesh's triangles
  };

  void build(const std::vector<Vec3f>& centroids, std::vector<uint32_t>& order);
  ClosestPoint finish(const Vec3f& q, uint32_t triangle) const;

  std::vector<Node> nodes_;
  std::vector<SearchTriangle> tris_;
  // Exact data for the final double-precision answer and the sign, by mesh index.
  std::vector<Vec3f> vertices_;
  std::vector<Triangle> triangles_;
  std::vector<uint8_t> degenerate_;    // per triangle: zero area, use its segments
  std::vector<Vec3f> face_normals_;    // per triangle, unit
  std::vector<Vec3f> edge_normals_;    // 3 per triangle, edge k = (v_k, v_(k+1)%3)
  std::vector<Vec3f> vertex_normals_;  // per vertex, angle-weighted
};

// Summary of a set of distances (mm). Percentiles interpolate linearly between order
// statistics (NumPy's default). All zero when count == 0.
struct DistanceStats {
  double mean = 0;
  double rms = 0;
  double p50 = 0;
  double p95 = 0;
  double p99 = 0;
  double max = 0;
  size_t count = 0;
};

// Takes the distances by value because it sorts them. NaNs are a programmer error.
DistanceStats summarize_distances(std::vector<float> distances);

// Two-sided comparison of a reconstruction with the true surface: `samples`
// area-uniform points on one mesh, distances to the other. output_to_truth measures
// accuracy (is every output point on the body?), truth_to_output completeness (is
// every part of the body reconstructed?); the larger of the two maxima is the
// Hausdorff distance up to sampling. Deterministic for a seed.
//
// A mesh without area yields no samples (count 0) in its direction, and infinite
// distances in the other.
struct MeshComparison {
  DistanceStats output_to_truth;
  DistanceStats truth_to_output;
};

MeshComparison compare_meshes(const TriangleMesh& output, const TriangleMesh& truth, size_t samples, uint64_t seed);

}  // namespace bodyscan
