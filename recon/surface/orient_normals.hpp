// Consistent normal orientation.
//
// Scanner data knows which camera saw each point, and a camera can only see the
// side of the surface facing it: orient_normals_toward_cameras() is exact there.
// Bare clouds use the thesis's minimum-spanning-tree propagation (§3.2.2.1, after
// Hoppe et al. 1992): a graph over the k nearest neighbours with cost
// 1 - |n_i . n_j|, a minimum spanning tree grown from a seed whose orientation is
// known, and each child flipped to agree with its parent.
#pragma once

#include <vector>

#include "recon/geometry/point_cloud.hpp"
#include "recon/spatial/knn_index.hpp"
#include "recon/surface/estimate_normals.hpp"

namespace bodyscan {

// Flips each frame whose normal points away from the centre of the camera that saw
// the point. Points without a known camera are left as they are. Returns how many
// points had a known camera.
// Caller guarantees: cloud.is_consistent(), frames has one entry per point.
size_t orient_normals_toward_cameras(const PointCloud& cloud, LocalFrames& frames);

struct OrientNormalsOptions {
  // Neighbours per point in the propagation graph (the graph is symmetrised, so a
  // point has about 2k edges). 6 orients bodies as well as 10 at a third of the cost.
  size_t k = 6;
  // Extra cost for an edge that leaves the tangent plane steeply, |n . d| for the
  // unit edge direction d: such edges tend to jump between the two sides of a thin
  // part (fingers, the gap between legs) where propagation would flip a whole side.
  float off_plane_cost = 0.5f;
};

struct OrientNormalsResult {
  size_t components = 0;  // connected components of the neighbour graph
  size_t flipped = 0;     // frames whose sign was changed
};

// Orients every frame consistently per connected component of the k-neighbour graph.
// Each component's seed is its highest point (max Y), whose normal is set to point up;
// afterwards a component whose normals point inward on the whole (sum of
// n . (p - centroid) < 0, i.e. negative enclosed volume for a closed surface) is
// flipped entirely, so closed surfaces end with outward normals.
// Caller guarantees: graph was built on `points` with at least options.k columns.
OrientNormalsResult orient_normals_mst(const std::vector<Vec3f>& points, const NeighborGraph& graph,
                                       LocalFrames& frames, const OrientNormalsOptions& options = {});

}  // namespace bodyscan
