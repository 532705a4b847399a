// Nearest-neighbour search over a fixed set of 3-D points (a nanoflann k-d tree).
#pragma once

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "recon/geometry/point_cloud.hpp"

namespace bodyscan {

class KnnIndex {
 public:
  // Builds the tree over `points` (any unit; the index keeps a reference, so the
  // vector must outlive the index and stay unchanged).
  explicit KnnIndex(const std::vector<Vec3f>& points);
  ~KnnIndex();
  KnnIndex(const KnnIndex&) = delete;
  KnnIndex& operator=(const KnnIndex&) = delete;

  // The k nearest points to q, nearest first: fills indices[0..n) and squared
  // distances[0..n), returns n = min(k, size()). Includes a point equal to q.
  size_t knn(const Vec3f& q, size_t k, uint32_t* indices, float* sq_distances) const;

  // All points within `radius` of q as (index, squared distance), nearest first;
  // in no particular order when nearest_first is false (faster: nothing is sorted).
  std::vector<std::pair<uint32_t, float>> within_radius(const Vec3f& q, float radius, bool nearest_first = true) const;

  size_t size() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Each point's k nearest other points: row i of `indices` / `distances` (k entries,
// nearest first, distances not squared) lists point i's neighbours without i itself.
// When the cloud has fewer than k+1 points, k is reduced to size()-1.
struct NeighborGraph {
  size_t k = 0;
  std::vector<uint32_t> indices;  // size() * k
  std::vector<float> distances;   // size() * k, same unit as the points
  const uint32_t* row(size_t i) const { return indices.data() + i * k; }
  const float* row_distances(size_t i) const { return distances.data() + i * k; }
};

// Builds the graph in parallel. Deterministic: the result does not depend on the
// number of threads.
NeighborGraph knn_graph(const KnnIndex& index, const std::vector<Vec3f>& points, size_t k);

}  // namespace bodyscan
