// Normals by principal component analysis of each point's nearest neighbours
// (thesis eq. 3.12-3.13, after Hoppe et al. 1992, "Surface reconstruction from
// unorganized points").
#pragma once

#include <vector>

#include "recon/geometry/point_cloud.hpp"
#include "recon/spatial/knn_index.hpp"

namespace bodyscan {

// Each point's local frame from the covariance of its neighbourhood: the normal is
// the eigenvector of the smallest eigenvalue, tangent1 that of the largest (the
// first principal direction of the tangent plane), tangent2 = normal x tangent1, so
// (tangent1, tangent2, normal) is right-handed. The sign of the normal is arbitrary
// here; orient_normals() fixes it.
struct LocalFrames {
  std::vector<Vec3f> normals;
  std::vector<Vec3f> tangent1;
  std::vector<Vec3f> tangent2;
  // Covariance eigenvalues, ascending (lambda0 <= lambda1 <= lambda2), mm^2: the
  // mean squared spread along normal, tangent2 and tangent1.
  std::vector<Vec3f> eigenvalues;
  // Each point minus the mean of its PCA neighbourhood (itself included), the
  // points' unit. A PCA normal is the surface's normal near that mean, not at the
  // point: where the neighbours lie to one side (the edge of what a camera saw) the
  // two differ, and correct_normal_tilt() (estimate_curvature.hpp) carries the
  // normal back to the point. Empty where unknown.
  std::vector<Vec3f> offset;
};

struct EstimateNormalsOptions {
  // Neighbours in each PCA (the point itself is added). More averages noise,
  // fewer keeps thin features.
  size_t k = 20;
};

// points: N points, any unit. Neighbours come from `graph` when it has options.k
// columns, else from `index` (a noisy cloud needs neighbourhoods wider than its
// noise, more than a graph is worth keeping for). Runs in parallel.
LocalFrames estimate_normals(const std::vector<Vec3f>& points, const KnnIndex& index, const NeighborGraph& graph,
                             const EstimateNormalsOptions& options = {});

// Flips each frame so that (tangent1, tangent2, normal) stays right-handed after the
// normal's sign was changed.
void flip_frame(LocalFrames& frames, size_t i);

}  // namespace bodyscan
