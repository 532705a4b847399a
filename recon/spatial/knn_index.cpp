#include "recon/spatial/knn_index.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <nanoflann.hpp>

#include <algorithm>

namespace bodyscan {

namespace {
struct PointAdaptor {
  const std::vector<Vec3f>& pts;
  size_t kdtree_get_point_count() const { return pts.size(); }
  float kdtree_get_pt(size_t i, size_t dim) const { return pts[i][static_cast<int>(dim)]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const {
    return false;
  }
};
using Tree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, PointAdaptor>, PointAdaptor, 3, uint32_t>;
}  // namespace

struct KnnIndex::Impl {
  explicit Impl(const std::vector<Vec3f>& p)
      : adaptor{p}, tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {
    tree.buildIndex();
  }
  PointAdaptor adaptor;
  Tree tree;
};

KnnIndex::KnnIndex(const std::vector<Vec3f>& points) : impl_(std::make_unique<Impl>(points)) {}
KnnIndex::~KnnIndex() = default;

size_t KnnIndex::size() const { return impl_->adaptor.pts.size(); }

size_t KnnIndex::knn(const Vec3f& q, size_t k, uint32_t* indices, float* sq_distances) const {
  k = std::min(k, size());
  if (k == 0) return 0;
  nanoflann::KNNResultSet<float, uint32_t, size_t> rs(k);
  rs.init(indices, sq_distances);
  impl_->tree.findNeighbors(rs, q.data(), nanoflann::SearchParams());
  return rs.size();
}

std::vector<std::pair<uint32_t, float>> KnnIndex::within_radius(const Vec3f& q, float radius,
                                                                bool nearest_first) const {
  std::vector<std::pair<uint32_t, float>> out;
  nanoflann::SearchParams params;
  params.sorted = nearest_first;
  impl_->tree.radiusSearch(q.data(), radius * radius, out, params);
  return out;
}

NeighborGraph knn_graph(const KnnIndex& index, const std::vector<Vec3f>& points, size_t k) {
  NeighborGraph g;
  const size_t n = points.size();
  g.k = n > 0 ? std::min(k, n - 1) : 0;
  if (g.k == 0) return g;
  g.indices.resize(n * g.k);
  g.distances.resize(n * g.k);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const tbb::blocked_range<size_t>& r) {
    std::vector<uint32_t> idx(g.k + 1);
    std::vector<float> d2(g.k + 1);
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const size_t got = index.knn(points[i], g.k + 1, idx.data(), d2.data());
      // Drop the point itself; with exact duplicates it may not come first.
      size_t out = 0;
      bool dropped = false;
      for (size_t j = 0; j < got && out < g.k; ++j) {
        if (!dropped && idx[j] == i) {
          dropped = true;
          continue;
        }
        g.indices[i * g.k + out] = idx[j];
        g.distances[i * g.k + out] = std::sqrt(d2[j]);
        ++out;
      }
    }
  });
  return g;
}

}  // namespace bodyscan
