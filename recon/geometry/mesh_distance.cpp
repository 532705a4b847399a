// Closest points on a triangle mesh through a bounding-volume hierarchy.
//
// Build: binned surface-area heuristic (I. Wald, "On fast construction of SAH-based
// bounding volume hierarchies", IEEE Symp. Interactive Ray Tracing, 2007), O(T log T).
// Query: depth-first, nearer child first, pruning every box farther than the best
// triangle so far. The search runs in float; the winning triangle is then solved again
// in double so that the reported distance is as exact as the float inputs allow.
// Sign: angle-weighted pseudonormals (Bærentzen & Aanæs 2005), see the header.
#include "recon/geometry/mesh_distance.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <numeric>
#include <unordered_map>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "recon/geometry/sample_surface.hpp"

namespace bodyscan {

namespace {

constexpr uint32_t kLeafSize = 4;
constexpr int kSahBins = 16;
// Past this depth splits are by median, which halves the count, so the tree depth is
// bounded by kMaxSahDepth + log2(T) whatever the triangle distribution.
constexpr uint32_t kMaxSahDepth = 40;
constexpr int kMaxStack = 96;
constexpr uint32_t kDegenerateBit = 0x80000000u;

// Which part of a triangle holds the closest point: corners 0..2, edges 3..5 where
// edge k joins corners k and (k + 1) % 3, or the interior.
enum Feature : int { kVertex0 = 0, kEdge0 = 3, kFace = 6 };

template <typename S>
using Vec3 = Eigen::Matrix<S, 3, 1>;

// Parameter of the point of segment origin + t·dir nearest to origin + offset, t in [0, 1].
template <typename S>
S segment_parameter(const Vec3<S>& offset, const Vec3<S>& dir) {
  const S dd = dir.squaredNorm();
  if (!(dd > 0)) return 0;
  return std::clamp(offset.dot(dir) / dd, S(0), S(1));
}

// Closest point to p on the three edges of triangle (a, a + ab, a + ac): what a
// zero-area triangle is.
template <typename S>
Vec3<S> closest_on_edges(const Vec3<S>& p, const Vec3<S>& a, const Vec3<S>& ab, const Vec3<S>& ac, int* feature) {
  const Vec3<S> ap = p - a;
  const Vec3<S> bc = ac - ab;
  const Vec3<S> candidates[3] = {a + segment_parameter(ap, ab) * ab, a + ab + segment_parameter<S>(ap - ab, bc) * bc,
                                 a + segment_parameter(ap, ac) * ac};
  const int features[3] = {kEdge0, kEdge0 + 1, kEdge0 + 2};
  int best = 0;
  S best_d2 = (p - candidates[0]).squaredNorm();
  for (int k = 1; k < 3; ++k) {
    const S d2 = (p - candidates[k]).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best = k;
    }
  }
  if (feature) *feature = features[best];
  return candidates[best];
}

// Ericson, Real-Time Collision Detection, §5.1.5 (ClosestPtPointTriangle): classify p
// against the Voronoi regions of the corners, then of the edges, else the face. The
// triangle is (a, b = a + ab, c = a + ac) and must have non-zero area; divisions are
// guarded anyway so that a sliver never produces NaN.
template <typename S>
Vec3<S> closest_on_triangle(const Vec3<S>& p, const Vec3<S>& a, const Vec3<S>& ab, const Vec3<S>& ac, int* feature) {
  const Vec3<S> ap = p - a;
  const S d1 = ab.dot(ap);
  const S d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) {
    if (feature) *feature = kVertex0;
    return a;
  }
  const Vec3<S> bp = ap - ab;
  const S d3 = ab.dot(bp);
  const S d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) {
    if (feature) *feature = kVertex0 + 1;
    return a + ab;
  }
  const S vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const S den = d1 - d3;
    if (feature) *feature = kEdge0;
    return a + (den > 0 ? d1 / den : S(0)) * ab;
  }
  const Vec3<S> cp = ap - ac;
  const S d5 = ab.dot(cp);
  const S d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) {
    if (feature) *feature = kVertex0 + 2;
    return a + ac;
  }
  const S vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const S den = d2 - d6;
    if (feature) *feature = kEdge0 + 2;
    return a + (den > 0 ? d2 / den : S(0)) * ac;
  }
  const S va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const S num = d4 - d3;
    const S den = num + (d5 - d6);
    if (feature) *feature = kEdge0 + 1;
    return a + ab + (den > 0 ? num / den : S(0)) * (ac - ab);
  }
  const S sum = va + vb + vc;  // = |ab × ac|², only rounding makes it non-positive
  if (!(sum > 0)) return closest_on_edges(p, a, ab, ac, feature);
  if (feature) *feature = kFace;
  return a + (vb / sum) * ab + (vc / sum) * ac;
}

struct Box {
  Vec3f lo = Vec3f::Constant(std::numeric_limits<float>::infinity());
  Vec3f hi = Vec3f::Constant(-std::numeric_limits<float>::infinity());
  // In plain floats: the tree's build grows boxes for every triangle at every
  // level, and the sanitizers' build does not inline Eigen's small expressions.
  void grow(const Vec3f& p) { grow(p, p); }
  void grow(const Box& b) { grow(b.lo, b.hi); }
  void grow(const Vec3f& low, const Vec3f& high) {
    float* l = lo.data();
    float* h = hi.data();
    const float* a = low.data();
    const float* b = high.data();
    for (int k = 0; k < 3; ++k) {
      l[k] = std::min(l[k], a[k]);
      h[k] = std::max(h[k], b[k]);
    }
  }
  // Half the surface area: the SAH only compares areas.
  float half_area() const {
    if (!(hi.x() >= lo.x())) return 0;
    const Vec3f e = hi - lo;
    return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
  }
};

uint64_t edge_key(uint32_t i, uint32_t j) {
  if (i > j) std::swap(i, j);
  return (static_cast<uint64_t>(i) << 32) | j;
}

// Squared distance from q to a box; 0 inside.
inline float box_distance2(const float q[3], const float lo[3], const float hi[3]) {
  float d2 = 0;
  for (int k = 0; k < 3; ++k) {
    const float d = std::max(std::max(lo[k] - q[k], q[k] - hi[k]), 0.0f);
    d2 += d * d;
  }
  return d2;
}

// Interleaves 21 bits per axis of q's position in the box (lo, lo + extent); NaN and
// out-of-box positions clamp to the box.
uint64_t morton_code(const Vec3f& q, const Vec3f& lo, const Vec3f& extent) {
  uint64_t code = 0;
  for (int k = 0; k < 3; ++k) {
    float unit = (q[k] - lo[k]) / extent[k];
    unit = unit > 0 ? std::min(unit, 1.0f) : 0.0f;
    uint64_t x = static_cast<uint64_t>(unit * 2097151.0f);  // 2^21 - 1
    x = (x | (x << 32)) & 0x1f00000000ffffull;
    x = (x | (x << 16)) & 0x1f0000ff0000ffull;
    x = (x | (x << 8)) & 0x100f00f00f00f00full;
    x = (x | (x << 4)) & 0x10c30c30c30c30c3ull;
    x = (x | (x << 2)) & 0x1249249249249249ull;
    code |= x << k;
  }
  return code;
}

uint64_t splitmix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

}  // namespace

Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c) {
  int feature = 0;
  return closest_on_triangle<double>(p, a, b - a, c - a, &feature);
}

MeshDistance::MeshDistance(const TriangleMesh& mesh) : vertices_(mesh.vertices), triangles_(mesh.triangles) {
  const size_t num = triangles_.size();
  assert(num < kDegenerateBit);
  degenerate_.assign(num, 0);
  face_normals_.assign(num, Vec3f::Zero());
  edge_normals_.assign(3 * num, Vec3f::Zero());
  vertex_normals_.assign(vertices_.size(), Vec3f::Zero());

  // Pseudonormals, accumulated in double. A zero-area triangle has no normal and adds
  // nothing; its closest points then take the sign of its neighbours' edges.
  std::vector<Vec3d> vertex_sum(vertices_.size(), Vec3d::Zero());
  std::unordered_map<uint64_t, Vec3d> edge_sum;
  edge_sum.reserve(num * 3 / 2 + 1);
  std::vector<Vec3f> centroids(num);
  for (size_t t = 0; t < num; ++t) {
    const Triangle& tri = triangles_[t];
    assert(tri[0] < vertices_.size() && tri[1] < vertices_.size() && tri[2] < vertices_.size());
    const Vec3d p[3] = {vertices_[tri[0]].cast<double>(), vertices_[tri[1]].cast<double>(),
                        vertices_[tri[2]].cast<double>()};
    centroids[t] = ((p[0] + p[1] + p[2]) / 3.0).cast<float>();
    const Vec3d cross = (p[1] - p[0]).cross(p[2] - p[0]);
    const double longest2 =
        std::max({(p[1] - p[0]).squaredNorm(), (p[2] - p[1]).squaredNorm(), (p[0] - p[2]).squaredNorm()});
    // Thinner than 1e-7 of its length: the edges are then within that of the true
    // answer, and the face formulas would divide by (almost) zero.
    if (!(cross.norm() > 1e-7 * longest2)) {
      degenerate_[t] = 1;
      continue;
    }
    const Vec3d n = cross.normalized();
    face_normals_[t] = n.cast<float>();
    for (int k = 0; k < 3; ++k) {
      const Vec3d e1 = (p[(k + 1) % 3] - p[k]).normalized();
      const Vec3d e2 = (p[(k + 2) % 3] - p[k]).normalized();
      const double angle = std::acos(std::clamp(e1.dot(e2), -1.0, 1.0));
      vertex_sum[tri[k]] += angle * n;
      auto [it, inserted] = edge_sum.try_emplace(edge_key(tri[k], tri[(k + 1) % 3]), n);
      if (!inserted) it->second += n;
    }
  }
  for (size_t v = 0; v < vertices_.size(); ++v) {
    if (vertex_sum[v].squaredNorm() > 0) vertex_normals_[v] = vertex_sum[v].normalized().cast<float>();
  }
  for (size_t t = 0; t < num; ++t) {
    for (int k = 0; k < 3; ++k) {
      auto it = edge_sum.find(edge_key(triangles_[t][k], triangles_[t][(k + 1) % 3]));
      if (it != edge_sum.end() && it->second.squaredNorm() > 0) {
        edge_normals_[3 * t + k] = it->second.normalized().cast<float>();
      }
    }
  }

  if (num == 0) return;
  std::vector<uint32_t> order(num);
  std::iota(order.begin(), order.end(), 0u);
  build(centroids, order);

  tris_.resize(num);
  for (size_t i = 0; i < num; ++i) {
    const uint32_t t = order[i];
    const Triangle& tri = triangles_[t];
    const Vec3d a = vertices_[tri[0]].cast<double>();
    tris_[i].a = vertices_[tri[0]];
    tris_[i].ab = (vertices_[tri[1]].cast<double>() - a).cast<float>();
    tris_[i].ac = (vertices_[tri[2]].cast<double>() - a).cast<float>();
    tris_[i].id = t | (degenerate_[t] ? kDegenerateBit : 0u);
  }
}

void MeshDistance::build(const std::vector<Vec3f>& centroids, std::vector<uint32_t>& order) {
  const size_t num = order.size();
  std::vector<Box> tri_boxes(num);
  for (size_t t = 0; t < num; ++t) {
    for (int k = 0; k < 3; ++k) tri_boxes[t].grow(vertices_[triangles_[t][k]]);
  }

  struct Task {
    uint32_t node, begin, end, depth;
  };
  nodes_.clear();
  nodes_.reserve(2 * ((num + kLeafSize - 1) / kLeafSize) + 1);
  nodes_.push_back({});
  std::vector<Task> tasks = {{0, 0, static_cast<uint32_t>(num), 0}};
  while (!tasks.empty()) {
    const Task task = tasks.back();
    tasks.pop_back();

    Box box, centroid_box;
    for (uint32_t i = task.begin; i < task.end; ++i) {
      box.grow(tri_boxes[order[i]]);
      centroid_box.grow(centroids[order[i]]);
    }
    Node& node = nodes_[task.node];
    for (int k = 0; k < 3; ++k) {
      node.lo[k] = box.lo[k];
      node.hi[k] = box.hi[k];
    }
    const uint32_t count = task.end - task.begin;
    if (count <= kLeafSize) {
      node.first = task.begin;
      node.count = count;
      continue;
    }

    int axis = 0;
    const Vec3f extent = centroid_box.hi - centroid_box.lo;
    if (extent.y() > extent[axis]) axis = 1;
    if (extent.z() > extent[axis]) axis = 2;
    auto* first = order.data() + task.begin;
    auto* last = order.data() + task.end;
    uint32_t* mid = nullptr;

    if (extent[axis] > 0 && task.depth < kMaxSahDepth) {
      const float lo = centroid_box.lo[axis];
      const float scale = kSahBins / extent[axis];
      auto bin_of = [&](uint32_t t) {
        return std::min(static_cast<int>((centroids[t][axis] - lo) * scale), kSahBins - 1);
      };
      Box bin_box[kSahBins];
      uint32_t bin_count[kSahBins] = {};
      for (auto* it = first; it != last; ++it) {
        const int b = bin_of(*it);
        bin_box[b].grow(tri_boxes[*it]);
        ++bin_count[b];
      }
      // cost[i]: split after bin i, area × count summed over both sides.
      float cost[kSahBins - 1];
      Box left;
      uint32_t left_count = 0;
      for (int i = 0; i < kSahBins - 1; ++i) {
        left.grow(bin_box[i]);
        left_count += bin_count[i];
        cost[i] = left.half_area() * static_cast<float>(left_count);
      }
      Box right;
      uint32_t right_count = 0;
      for (int i = kSahBins - 1; i > 0; --i) {
        right.grow(bin_box[i]);
        right_count += bin_count[i];
        cost[i - 1] += right.half_area() * static_cast<float>(right_count);
      }
      const int split = static_cast<int>(std::min_element(cost, cost + (kSahBins - 1)) - cost);
      mid = std::partition(first, last, [&](uint32_t t) { return bin_of(t) <= split; });
      if (mid == first || mid == last) mid = nullptr;  // only if rounding emptied a side
    }
    if (mid == nullptr) {
      mid = first + count / 2;
      std::nth_element(first, mid, last,
                       [&](uint32_t x, uint32_t y) { return centroids[x][axis] < centroids[y][axis]; });
    }

    const auto children = static_cast<uint32_t>(nodes_.size());
    nodes_[task.node].first = children;
    nodes_[task.node].count = 0;
    nodes_.push_back({});
    nodes_.push_back({});
    const auto split_at = static_cast<uint32_t>(mid - order.data());
    tasks.push_back({children, task.begin, split_at, task.depth + 1});
    tasks.push_back({children + 1, split_at, task.end, task.depth + 1});
  }
}

ClosestPoint MeshDistance::closest_point(const Vec3f& q) const {
  if (tris_.empty()) return {};
  const float qa[3] = {q.x(), q.y(), q.z()};
  float best = std::numeric_limits<float>::infinity();
  uint32_t best_index = 0;

  uint32_t stack[kMaxStack];
  float stack_distance[kMaxStack];
  int depth = 0;
  uint32_t current = 0;
  for (;;) {
    const Node& node = nodes_[current];
    if (node.count > 0) {
      for (uint32_t i = node.first; i < node.first + node.count; ++i) {
        const SearchTriangle& tri = tris_[i];
        const Vec3f p = (tri.id & kDegenerateBit) ? closest_on_edges<float>(q, tri.a, tri.ab, tri.ac, nullptr)
                                                  : closest_on_triangle<float>(q, tri.a, tri.ab, tri.ac, nullptr);
        const float d2 = (q - p).squaredNorm();
        if (d2 < best) {
          best = d2;
          best_index = i;
        }
      }
    } else {
      uint32_t near_child = node.first;
      uint32_t far_child = node.first + 1;
      float near_d2 = box_distance2(qa, nodes_[near_child].lo, nodes_[near_child].hi);
      float far_d2 = box_distance2(qa, nodes_[far_child].lo, nodes_[far_child].hi);
      if (far_d2 < near_d2) {
        std::swap(near_child, far_child);
        std::swap(near_d2, far_d2);
      }
      if (far_d2 < best) {
        assert(depth < kMaxStack);
        stack[depth] = far_child;
        stack_distance[depth] = far_d2;
        ++depth;
      }
      if (near_d2 < best) {
        current = near_child;
        continue;
      }
    }
    // Boxes pushed earlier may have fallen behind the best distance since.
    while (depth > 0 && !(stack_distance[depth - 1] < best)) --depth;
    if (depth == 0) break;
    current = stack[--depth];
  }
  return finish(q, tris_[best_index].id & ~kDegenerateBit);
}

ClosestPoint MeshDistance::finish(const Vec3f& q, uint32_t t) const {
  const Triangle& tri = triangles_[t];
  const Vec3d a = vertices_[tri[0]].cast<double>();
  const Vec3d ab = vertices_[tri[1]].cast<double>() - a;
  const Vec3d ac = vertices_[tri[2]].cast<double>() - a;
  const Vec3d p = q.cast<double>();
  int feature = kFace;
  const Vec3d c =
      degenerate_[t] ? closest_on_edges(p, a, ab, ac, &feature) : closest_on_triangle(p, a, ab, ac, &feature);
  const double distance = (p - c).norm();

  Vec3f pseudonormal;
  if (feature == kFace) {
    pseudonormal = face_normals_[t];
  } else if (feature >= kEdge0) {
    pseudonormal = edge_normals_[3 * t + (feature - kEdge0)];
  } else {
    pseudonormal = vertex_normals_[tri[feature - kVertex0]];
  }
  const bool inside = (p - c).dot(pseudonormal.cast<double>()) < 0;

  ClosestPoint result;
  result.point = c.cast<float>();
  result.distance = static_cast<float>(distance);
  result.triangle = t;
  result.signed_distance = static_cast<float>(inside ? -distance : distance);
  return result;
}

std::vector<float> MeshDistance::distances(const std::vector<Vec3f>& queries) const {
  std::vector<float> out(queries.size());
  // Answer the queries in Morton order of their positions: neighbouring queries walk
  // the same boxes and triangles, which then stay in cache (the tree of a 100k-triangle
  // mesh is several MB). Worth ~2x for scattered input such as random surface samples.
  Box bounds;
  for (const Vec3f& q : queries) bounds.grow(q);
  const Vec3f extent = (bounds.hi - bounds.lo).cwiseMax(Vec3f::Constant(1e-30f));
  std::vector<std::pair<uint64_t, uint32_t>> order(queries.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, queries.size(), 4096), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      order[i] = {morton_code(queries[i], bounds.lo, extent), static_cast<uint32_t>(i)};
    }
  });
  tbb::parallel_sort(order.begin(), order.end());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, queries.size(), 256), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const uint32_t k = order[i].second;
      out[k] = closest_point(queries[k]).distance;
    }
  });
  return out;
}

DistanceStats summarize_distances(std::vector<float> distances) {
  DistanceStats stats;
  stats.count = distances.size();
  if (distances.empty()) return stats;
  std::sort(distances.begin(), distances.end());
  assert(!std::isnan(distances.front()) && !std::isnan(distances.back()));
  double sum = 0;
  double sum2 = 0;
  for (float d : distances) {
    sum += d;
    sum2 += static_cast<double>(d) * d;
  }
  const auto n = static_cast<double>(distances.size());
  stats.mean = sum / n;
  stats.rms = std::sqrt(sum2 / n);
  auto percentile = [&](double fraction) {
    const double h = fraction * (n - 1);
    const auto lo = static_cast<size_t>(std::floor(h));
    const size_t hi = std::min(lo + 1, distances.size() - 1);
    const double x0 = distances[lo];
    const double x1 = distances[hi];
    // Equal neighbours skip the interpolation so that infinities do not become NaN.
    return x0 == x1 ? x0 : x0 + (h - static_cast<double>(lo)) * (x1 - x0);
  };
  stats.p50 = percentile(0.50);
  stats.p95 = percentile(0.95);
  stats.p99 = percentile(0.99);
  stats.max = distances.back();
  return stats;
}

MeshComparison compare_meshes(const TriangleMesh& output, const TriangleMesh& truth, size_t samples, uint64_t seed) {
  // Two different streams: comparing a mesh with itself must not sample the very same
  // points on both sides.
  const PointCloud on_output = sample_mesh_uniform(output, samples, splitmix64(seed), /*with_normals=*/false);
  const PointCloud on_truth = sample_mesh_uniform(truth, samples, splitmix64(seed ^ 0x5bd1e9955bd1e995ull), false);
  MeshComparison result;
  result.output_to_truth = summarize_distances(MeshDistance(truth).distances(on_output.positions));
  result.truth_to_output = summarize_distances(MeshDistance(output).distances(on_truth.positions));
  return result;
}

}  // namespace bodyscan
