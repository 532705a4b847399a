#include "recon/geometry/fill_holes.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <unordered_map>
#include <unordered_set>

#include <tsl/robin_map.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "recon/geometry/mesh_components.hpp"

namespace bodyscan {

namespace {

uint64_t key(uint32_t a, uint32_t b) { return (static_cast<uint64_t>(a) << 32) | b; }
uint64_t undirected_key(uint32_t a, uint32_t b) { return a < b ? key(a, b) : key(b, a); }
// The keys' both halves mixed into the low bits an open-addressing table indexes by.
struct EdgeHash {
  size_t operator()(uint64_t k) const {
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdull;
    k ^= k >> 33;
    return static_cast<size_t>(k);
  }
};

// Every triangle's half-edges filed under their start vertex (compressed rows).
struct HalfEdges {
  std::vector<size_t> start;
  std::vector<uint32_t> to;
  std::vector<uint32_t> triangle;

  explicit HalfEdges(const TriangleMesh& mesh) : start(mesh.vertices.size() + 1, 0) {
    for (const Triangle& t : mesh.triangles)
      for (uint32_t v : t) ++start[v + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    to.resize(start.back());
    triangle.resize(start.back());
    std::vector<size_t> fill(start.begin(), start.end() - 1);
    for (size_t i = 0; i < mesh.triangles.size(); ++i) {
      const Triangle& t = mesh.triangles[i];
      for (int k = 0; k < 3; ++k) {
        const size_t slot = fill[t[k]]++;
        to[slot] = t[(k + 1) % 3];
        triangle[slot] = static_cast<uint32_t>(i);
      }
    }
  }
  size_t count(uint32_t a, uint32_t b) const {
    if (a + 1 >= start.size()) return 0;
    size_t n = 0;
    for (size_t s = start[a]; s < start[a + 1]; ++s) n += to[s] == b;
    return n;
  }
  long find(uint32_t a, uint32_t b) const {
    if (a + 1 >= start.size()) return -1;
    for (size_t s = start[a]; s < start[a + 1]; ++s)
      if (to[s] == b) return static_cast<long>(triangle[s]);
    return -1;
  }
  bool connected(uint32_t a, uint32_t b) const { return count(a, b) + count(b, a) > 0; }
};

// The boundary half-edges (a -> b used once, b -> a never) as (a, b, triangle),
// sorted. A parallel pass over the vertices: on a closed mesh of millions of
// triangles this is all the hole filling costs.
struct BoundaryEdge {
  uint32_t from, to, triangle;
  bool operator<(const BoundaryEdge& o) const { return from != o.from ? from < o.from : to < o.to; }
};
std::vector<BoundaryEdge> boundary_edges(const HalfEdges& he) {
  const size_t nv = he.start.size() - 1;
  tbb::enumerable_thread_specific<std::vector<BoundaryEdge>> found;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, 4096), [&](const tbb::blocked_range<size_t>& r) {
    auto& local = found.local();
    for (size_t a = r.begin(); a != r.end(); ++a) {
      for (size_t s = he.start[a]; s < he.start[a + 1]; ++s) {
        const uint32_t b = he.to[s];
        if (he.count(b, static_cast<uint32_t>(a)) == 0 && he.count(static_cast<uint32_t>(a), b) == 1) {
          local.push_back({static_cast<uint32_t>(a), b, he.triangle[s]});
        }
      }
    }
  });
  std::vector<BoundaryEdge> all;
  for (auto& local : found) all.insert(all.end(), local.begin(), local.end());
  std::sort(all.begin(), all.end());
  return all;
}

// The boundary loops, each in the mesh's own half-edge direction, split where a
// loop passes a vertex twice so that every loop visits its vertices once.
std::vector<std::vector<uint32_t>> boundary_loops(const std::vector<BoundaryEdge>& boundary) {
  std::vector<std::pair<uint32_t, uint32_t>> edges;  // (from, to), sorted
  edges.reserve(boundary.size());
  for (const BoundaryEdge& e : boundary) edges.emplace_back(e.from, e.to);
  std::vector<uint8_t> used(edges.size(), 0);
  auto next_from = [&](uint32_t v) -> long {
    auto it = std::lower_bound(edges.begin(), edges.end(), std::make_pair(v, uint32_t{0}));
    for (; it != edges.end() && it->first == v; ++it) {
      const size_t i = static_cast<size_t>(it - edges.begin());
      if (!used[i]) return static_cast<long>(i);
    }
    return -1;
  };

  std::vector<std::vector<uint32_t>> loops;
  for (size_t e0 = 0; e0 < edges.size(); ++e0) {
    if (used[e0]) continue;
    std::vector<uint32_t> seq{edges[e0].first};
    long e = static_cast<long>(e0);
    bool closed = false;
    while (e >= 0) {
      used[static_cast<size_t>(e)] = 1;
      const uint32_t b = edges[static_cast<size_t>(e)].second;
      if (b == seq.front()) {
        closed = true;
        break;
      }
      seq.push_back(b);
      e = next_from(b);
    }
    if (!closed) continue;  // only on a non-manifold boundary; left open
    // Split at repeated vertices.
    std::vector<uint32_t> stack;
    std::unordered_map<uint32_t, size_t> position;
    auto emit = [&](size_t from) {
      std::vector<uint32_t> loop(stack.begin() + static_cast<long>(from), stack.end());
      for (uint32_t v : loop) position.erase(v);
      stack.resize(from);
      if (loop.size() >= 3) loops.push_back(std::move(loop));
    };
    for (uint32_t v : seq) {
      auto it = position.find(v);
      if (it != position.end()) emit(it->second);
      position[v] = stack.size();
      stack.push_back(v);
    }
    emit(0);
  }
  return loops;
}

// The edges earlier patches added, findable by key and from either end.
struct AddedEdges {
  std::unordered_set<uint64_t> keys;
  std::unordered_map<uint32_t, std::vector<uint32_t>> neighbours;
  void insert(uint32_t a, uint32_t b) {
    if (!keys.insert(undirected_key(a, b)).second) return;
    neighbours[a].push_back(b);
    neighbours[b].push_back(a);
  }
  bool contains(uint32_t a, uint32_t b) const { return keys.count(undirected_key(a, b)) > 0; }
};

// Whether min(a[k], b[k]) < t for all four k (false for a NaN).
inline bool all_below(const float* a, const float* b, float t) {
#ifdef __SSE2__
  const __m128 bound = _mm_min_ps(_mm_loadu_ps(a), _mm_loadu_ps(b));
  return _mm_movemask_ps(_mm_cmplt_ps(bound, _mm_set1_ps(t))) == 0xf;
#else
  for (int k = 0; k < 4; ++k)
    if (!(std::min(a[k], b[k]) < t)) return false;
  return true;
#endif
}

Vec3f unit_normal(const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  const Vec3f n = (b - a).cross(c - a);
  const float len = n.norm();
  return len > 0.f ? Vec3f(n / len) : Vec3f::Zero();
}

// One hole being filled: the patch triangles and what the filling needs to know
// about the mesh around them. The mesh is only read; the patch's own vertices are
// numbered from first_new_vertex (the mesh's vertex count when they are appended
// in order) and kept apart until commit(), so that patches of holes with no
// vertex in common can be made side by side.
class HolePatch {
 public:
  HolePatch(const TriangleMesh& mesh, const HalfEdges& he, const AddedEdges& added_edges, uint32_t first_new_vertex)
      : mesh_(mesh), he_(he), added_(added_edges), first_new_vertex_(first_new_vertex) {}

  // Triangulates the polygon (fill winding: consecutive vertices are the new
  // triangles' edges). `edge_normal[k]` is the unit normal of the mesh triangle on
  // edge k -> k+1 (zero when unknown).
  void triangulate(const std::vector<uint32_t>& poly, const std::vector<Vec3f>& edge_normal, size_t max_dp) {
    const size_t n = poly.size();
    if (n == 3) {
      add({poly[0], poly[1], poly[2]});
      return;
    }
    if (n > max_dp) {
      size_t si = 0, sj = 0;
      if (find_split(poly, edge_normal, &si, &sj)) {
        std::vector<uint32_t> a(poly.begin() + static_cast<long>(si), poly.begin() + static_cast<long>(sj) + 1);
        std::vector<Vec3f> na(edge_normal.begin() + static_cast<long>(si), edge_normal.begin() + static_cast<long>(sj));
        na.push_back(Vec3f::Zero());  // the diagonal
        std::vector<uint32_t> b(poly.begin() + static_cast<long>(sj), poly.end());
        b.insert(b.end(), poly.begin(), poly.begin() + static_cast<long>(si) + 1);
        std::vector<Vec3f> nb(edge_normal.begin() + static_cast<long>(sj), edge_normal.end());
        nb.insert(nb.end(), edge_normal.begin(), edge_normal.begin() + static_cast<long>(si));
        nb.push_back(Vec3f::Zero());
        diagonals_.insert(undirected_key(poly[si], poly[sj]));
        triangulate(a, na, max_dp);
        triangulate(b, nb, max_dp);
        return;
      }
    }
    if (!minimum_dihedral_triangulation(poly, edge_normal)) fan(poly);
  }

  void refine() {
    constexpr float kAlpha = 1.41421356f;  // Liepa's density factor sqrt(2)
    for (const Triangle& t : tris_)
      for (uint32_t v : t) scale_of(v);
    for (int pass = 0; pass < 30; ++pass) {
      bool split = false;
      const size_t count = tris_.size();
      for (size_t i = 0; i < count; ++i) {
        const Triangle t = tris_[i];
        const Vec3f c = (pos(t[0]) + pos(t[1]) + pos(t[2])) / 3.f;
        const float sc = (scale_[t[0]] + scale_[t[1]] + scale_[t[2]]) / 3.f;
        bool big = true;
        for (uint32_t v : t) {
          const float d = kAlpha * (c - pos(v)).norm();
          big = big && d > sc && d > scale_[v];
        }
        if (!big) continue;
        const uint32_t m = next_vertex();
        new_vertices_.push_back(c);
        scale_[m] = sc;
        remove_edges(i);
        tris_[i] = {t[0], t[1], m};
        insert_edges(i);
        add({t[1], t[2], m});
        add({t[2], t[0], m});
        relax(t[0], t[1]);
        relax(t[1], t[2]);
        relax(t[2], t[0]);
        split = true;
      }
      for (int r = 0; r < 50; ++r) {
        bool flipped = false;
        for (size_t i = 0; i < tris_.size(); ++i) {
          for (int k = 0; k < 3; ++k) flipped = relax(tris_[i][k], tris_[i][(k + 1) % 3]) || flipped;
        }
        if (!flipped) break;
      }
      if (!split) break;
    }
  }

  // New vertices minimise sum |L v|^2, L the umbrella operator (mean of the
  // neighbours minus the vertex), over the new vertices (membrane) or over the new
  // and the loop's vertices (thin plate: the loop's rings pull the patch along the
  // surrounding curvature).
  void fair(const std::vector<uint32_t>& loop, bool thin_plate) {
    const uint32_t nv = next_vertex();
    const uint32_t k = nv - first_new_vertex_;
    if (k == 0) return;
    std::unordered_map<uint32_t, std::vector<uint32_t>> ring;
    auto link = [&](uint32_t a, uint32_t b) {
      auto& r = ring[a];
      if (std::find(r.begin(), r.end(), b) == r.end()) r.push_back(b);
    };
    for (const Triangle& t : tris_)
      for (int j = 0; j < 3; ++j) {
        link(t[j], t[(j + 1) % 3]);
        link(t[(j + 1) % 3], t[j]);
      }
    for (uint32_t v : loop) {
      for (size_t s = he_.start[v]; s < he_.start[v + 1]; ++s) {
        const Triangle& t = mesh_.triangles[he_.triangle[s]];
        for (uint32_t u : t)
          if (u != v) link(v, u);
      }
    }
    std::vector<Eigen::Triplet<double>> triplets;
    std::vector<Vec3d> rhs;
    size_t row = 0;
    auto add_row = [&](uint32_t v) {
      const auto& r = ring[v];
      if (r.empty()) return;
      const double w = 1.0 / static_cast<double>(r.size());
      Vec3d b = Vec3d::Zero();
      auto put = [&](uint32_t u, double c) {
        if (u >= first_new_vertex_) {
          triplets.emplace_back(static_cast<int>(row), static_cast<int>(u - first_new_vertex_), c);
        } else {
          b -= c * pos(u).cast<double>();
        }
      };
      for (uint32_t u : r) put(u, w);
      put(v, -1.0);
      rhs.push_back(b);
      ++row;
    };
    for (uint32_t v = first_new_vertex_; v < nv; ++v) add_row(v);
    if (thin_plate)
      for (uint32_t v : loop) add_row(v);
    Eigen::SparseMatrix<double> a(static_cast<int>(row), static_cast<int>(k));
    a.setFromTriplets(triplets.begin(), triplets.end());
    Eigen::MatrixXd b(static_cast<int>(row), 3);
    for (size_t i = 0; i < row; ++i) b.row(static_cast<int>(i)) = rhs[i].transpose();
    const Eigen::SparseMatrix<double> normal = a.transpose() * a;
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(normal);
    if (solver.info() != Eigen::Success) return;
    const Eigen::MatrixXd x = solver.solve(a.transpose() * b);
    if (solver.info() != Eigen::Success || !x.allFinite()) return;
    for (uint32_t i = 0; i < k; ++i) new_vertices_[i] = x.row(static_cast<int>(i)).transpose().cast<float>();
  }

  const std::vector<Triangle>& triangles() const { return tris_; }
  double area() const {
    double sum = 0.0;
    for (const Triangle& t : tris_)
      sum += 0.5 * static_cast<double>((pos(t[1]) - pos(t[0])).cross(pos(t[2]) - pos(t[0])).norm());
    return sum;
  }
  // Forgets the patch and any vertex it added.
  void discard() {
    tris_.clear();
    edges_.clear();
    diagonals_.clear();
    new_vertices_.clear();
  }
  const std::vector<Vec3f>& new_vertices() const { return new_vertices_; }

 private:
  const Vec3f& pos(uint32_t v) const {
    return v < first_new_vertex_ ? mesh_.vertices[v] : new_vertices_[v - first_new_vertex_];
  }
  uint32_t next_vertex() const { return first_new_vertex_ + static_cast<uint32_t>(new_vertices_.size()); }

  // An edge the patch may not create: it exists in the mesh, in another patch, or
  // in this one.
  bool edge_taken(uint32_t a, uint32_t b) const {
    return (a < first_new_vertex_ && b < first_new_vertex_ && he_.connected(a, b)) || added_.contains(a, b) ||
           diagonals_.count(undirected_key(a, b)) > 0 || edges_.count(key(a, b)) > 0 || edges_.count(key(b, a)) > 0;
  }

  // edge_taken for every pair of the polygon's vertices (n x n, symmetric), found
  // from the vertices' own edges - the mesh's, earlier patches', this patch's -
  // rather than by n^2 / 2 lookups.
  std::vector<uint8_t> taken_pairs(const std::vector<uint32_t>& poly) const {
    const size_t n = poly.size();
    std::vector<uint8_t> taken(n * n, 0);
    std::unordered_map<uint32_t, uint32_t> slot;
    slot.reserve(2 * n);
    for (size_t k = 0; k < n; ++k) slot.emplace(poly[k], static_cast<uint32_t>(k));
    auto mark = [&](size_t i, uint32_t b) {
      auto it = slot.find(b);
      if (it == slot.end()) return;
      taken[i * n + it->second] = taken[it->second * n + i] = 1;
    };
    for (size_t i = 0; i < n; ++i) {
      const uint32_t a = poly[i];
      if (a < first_new_vertex_ && a + 1 < he_.start.size())
        for (size_t s = he_.start[a]; s < he_.start[a + 1]; ++s)
          if (he_.to[s] < first_new_vertex_) mark(i, he_.to[s]);
      auto it = added_.neighbours.find(a);
      if (it != added_.neighbours.end())
        for (uint32_t b : it->second) mark(i, b);
    }
    for (const Triangle& t : tris_)
      for (int k = 0; k < 3; ++k) {
        auto it = slot.find(t[k]);
        if (it != slot.end()) mark(it->second, t[(k + 1) % 3]);
      }
    for (uint64_t d : diagonals_) {
      auto it = slot.find(static_cast<uint32_t>(d >> 32));
      if (it != slot.end()) mark(it->second, static_cast<uint32_t>(d));
    }
    return taken;
  }

  float scale_of(uint32_t v) {
    auto it = scale_.find(v);
    if (it != scale_.end()) return it->second;
    double sum = 0.0;
    size_t n = 0;
    if (v + 1 < he_.start.size()) {
      for (size_t s = he_.start[v]; s < he_.start[v + 1]; ++s, ++n) sum += (pos(he_.to[s]) - pos(v)).norm();
    }
    float value = n ? static_cast<float>(sum / static_cast<double>(n)) : 0.f;
    if (n == 0) {  // a vertex with no mesh edges: its patch edges
      for (const Triangle& t : tris_)
        for (int k = 0; k < 3; ++k)
          if (t[k] == v) value = std::max(value, (pos(t[(k + 1) % 3]) - pos(v)).norm());
    }
    scale_[v] = value;
    return value;
  }

  void insert_edges(size_t i) {
    const Triangle& t = tris_[i];
    for (int k = 0; k < 3; ++k) edges_[key(t[k], t[(k + 1) % 3])] = static_cast<uint32_t>(i);
  }
  void remove_edges(size_t i) {
    const Triangle& t = tris_[i];
    for (int k = 0; k < 3; ++k) edges_.erase(key(t[k], t[(k + 1) % 3]));
  }
  void add(const Triangle& t) {
    tris_.push_back(t);
    insert_edges(tris_.size() - 1);
  }

  // Flips edge a-b to the other diagonal of its two patch triangles when that
  // satisfies the Delaunay condition the current one breaks.
  bool relax(uint32_t a, uint32_t b) {
    auto i1 = edges_.find(key(a, b)), i2 = edges_.find(key(b, a));
    if (i1 == edges_.end() || i2 == edges_.end()) return false;  // on the loop
    const size_t t1 = i1->second, t2 = i2->second;
    auto third = [&](size_t t) {
      for (uint32_t v : tris_[t])
        if (v != a && v != b) return v;
      return a;
    };
    const uint32_t c = third(t1), d = third(t2);
    if (c == d) return false;
    auto angle = [&](uint32_t apex) {
      const Vec3f u = (pos(a) - pos(apex)).normalized(), w = (pos(b) - pos(apex)).normalized();
      return std::acos(std::clamp(u.dot(w), -1.f, 1.f));
    };
    if (angle(c) + angle(d) <= static_cast<float>(M_PI) + 1e-4f) return false;
    if (edge_taken(c, d)) return false;
    remove_edges(t1);
    remove_edges(t2);
    tris_[t1] = {a, d, c};
    tris_[t2] = {d, b, c};
    insert_edges(t1);
    insert_edges(t2);
    return true;
  }

  // A diagonal (i, j) cutting a long loop into two parts of at least a quarter of
  // it each, as short as possible. A diagonal that leaves the surface outward at
  // either end (along the surrounding triangles' normals) spans a gap outside the
  // body rather than the hole - between the inner thighs below the crotch, the
  // shortest of all - and is taken only when nothing else is left.
  bool find_split(const std::vector<uint32_t>& poly, const std::vector<Vec3f>& edge_normal, size_t* si,
                  size_t* sj) const {
    const size_t n = poly.size();
    const size_t min_part = std::max<size_t>(3, n / 4);
    std::vector<Vec3f> normal(n, Vec3f::Zero());
    for (size_t i = 0; i < n && edge_normal.size() == n; ++i) {
      const Vec3f v = edge_normal[i] + edge_normal[(i + n - 1) % n];
      if (v.squaredNorm() > 0.f) normal[i] = v.normalized();
    }
    double best = std::numeric_limits<double>::max();
    for (int pass = 0; pass < 2 && !(best < std::numeric_limits<double>::max()); ++pass) {
      for (size_t i = 0; i < n; ++i) {
        for (size_t j = i + min_part; j + min_part <= n + i && j < n; ++j) {
          const Vec3f dv = pos(poly[j]) - pos(poly[i]);
          const double d = dv.norm();
          if (pass == 0 && d > 0 && (normal[i].dot(dv) > 0.5f * d || normal[j].dot(-dv) > 0.5f * d)) continue;
          if (d < best && !edge_taken(poly[i], poly[j])) {
            best = d;
            *si = i;
            *sj = j;
          }
        }
      }
    }
    return best < std::numeric_limits<double>::max();
  }

  bool minimum_dihedral_triangulation(const std::vector<uint32_t>& poly, const std::vector<Vec3f>& edge_normal) {
    const size_t n = poly.size();
    // Cell (i, j): the best triangulation of the polygon i..j - its worst dihedral
    // angle's cosine (< -1: none), its area, the apex m of the triangle on i-j and
    // that triangle's normal. Kept as separate tables so the bound test below
    // reads only the cosines. Row-major tables serve the left cells (i, m) and
    // column-major copies the right cells (m, j): the innermost loop walks m and
    // every table it reads stays contiguous (a stride of n cells missed the cache
    // on every step of long loops).
    std::vector<float> cos_row(n * n, -2.f), cos_column(n * n, -2.f);
    std::vector<float> area_row(n * n, 0.f), area_column(n * n, 0.f);
    std::vector<Vec3f> normal_row(n * n, Vec3f::Zero()), normal_column(n * n, Vec3f::Zero());
    std::vector<int> apex(n * n, -1);
    std::vector<Vec3f> p(n);
    for (size_t k = 0; k < n; ++k) p[k] = pos(poly[k]);
    const std::vector<uint8_t> taken = taken_pairs(poly);
    for (size_t i = 0; i + 1 < n; ++i) cos_row[i * n + i + 1] = cos_column[(i + 1) * n + i] = 1.f;
    // Cell (i, i + len) needs only shorter cells: each length's cells are solved
    // in parallel once the previous lengths are done.
    auto solve = [&](size_t i, size_t len) {
      const size_t j = i + len;
      if (len < n - 1 && taken[i * n + j]) return;
      float best_cos = -2.f, best_area = 0.f;
      int best_m = -1;
      Vec3f best_normal = Vec3f::Zero();
      const Vec3f& pi = p[i];
      const Vec3f pij = p[j] - pi;
      const float* left_cos = &cos_row[i * n];
      const float* right_cos = &cos_column[j * n];
      auto consider = [&](size_t m) __attribute__((always_inline)) {
        // The candidate's worst angle is no better than its two parts': when
        // that bound already loses to the best so far, the triangle's geometry
        // cannot change the outcome (an exact pruning: the same triangulation).
        const float bound = std::min(left_cos[m], right_cos[m]);
        if (bound < -1.5f || bound < best_cos - 1e-6f) return;
        const Vec3f nrm = (p[m] - pi).cross(pij);
        const float twice_area = nrm.norm();
        const Vec3f u = twice_area > 0.f ? Vec3f(nrm / twice_area) : Vec3f::Zero();
        float c = twice_area > 0.f ? bound : -1.f;  // degenerate: the worst angle
        const Vec3f& n_left = m == i + 1 ? edge_normal[i] : normal_row[i * n + m];
        const Vec3f& n_right = j == m + 1 ? edge_normal[m] : normal_column[j * n + m];
        if (!n_left.isZero()) c = std::min(c, u.dot(n_left));
        if (!n_right.isZero()) c = std::min(c, u.dot(n_right));
        if (len == n - 1 && !edge_normal[n - 1].isZero()) c = std::min(c, u.dot(edge_normal[n - 1]));
        const float area = area_row[i * n + m] + area_column[j * n + m] + 0.5f * twice_area;
        if (c > best_cos + 1e-6f || (c >= best_cos - 1e-6f && area < best_area)) {
          best_cos = c;
          best_area = area;
          best_m = static_cast<int>(m);
          best_normal = u;
        }
      };
      // Four candidates at a time are passed over together when none of their
      // bounds reaches the best so far - most of them, once a good one is found.
      size_t m = i + 1;
      for (; m + 4 <= j; m += 4) {
        if (all_below(left_cos + m, right_cos + m, std::max(-1.5f, best_cos - 1e-6f))) continue;
        for (size_t k = m; k < m + 4; ++k) consider(k);
      }
      for (; m < j; ++m) consider(m);
      cos_row[i * n + j] = cos_column[j * n + i] = best_cos;
      area_row[i * n + j] = area_column[j * n + i] = best_area;
      normal_row[i * n + j] = normal_column[j * n + i] = best_normal;
      apex[i * n + j] = best_m;
    };
    for (size_t len = 2; len < n; ++len) {
      const size_t cells = n - len;
      if (cells * len < 1u << 14) {
        for (size_t i = 0; i < cells; ++i) solve(i, len);
      } else {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, cells, 16), [&](const tbb::blocked_range<size_t>& r) {
          for (size_t i = r.begin(); i != r.end(); ++i) solve(i, len);
        });
      }
    }
    auto at = [&](size_t i, size_t j) { return apex[i * n + j]; };
    if (at(0, n - 1) < 0) return false;
    std::vector<std::pair<size_t, size_t>> stack{{0, n - 1}};
    while (!stack.empty()) {
      const auto [i, j] = stack.back();
      stack.pop_back();
      const size_t m = static_cast<size_t>(at(i, j));
      add({poly[i], poly[m], poly[j]});
      if (m - i >= 2) stack.emplace_back(i, m);
      if (j - m >= 2) stack.emplace_back(m, j);
    }
    return true;
  }

  // Fallback: a fan around a new vertex at the loop's centroid.
  void fan(const std::vector<uint32_t>& poly) {
    Vec3f c = Vec3f::Zero();
    for (uint32_t v : poly) c += pos(v);
    c /= static_cast<float>(poly.size());
    const uint32_t m = next_vertex();
    new_vertices_.push_back(c);
    for (size_t k = 0; k < poly.size(); ++k) add({poly[k], poly[(k + 1) % poly.size()], m});
  }

  const TriangleMesh& mesh_;
  const HalfEdges& he_;
  const AddedEdges& added_;
  const uint32_t first_new_vertex_;
  std::vector<Vec3f> new_vertices_;  // vertex first_new_vertex_ + i
  std::vector<Triangle> tris_;
  tsl::robin_map<uint64_t, uint32_t, EdgeHash> edges_;  // directed patch edge -> patch triangle
  std::unordered_set<uint64_t> diagonals_;              // the splits' diagonals (undirected)
  std::unordered_map<uint32_t, float> scale_;           // local edge length per vertex
};

// Holes joined through shared vertices, each group in loop order, the groups in
// the order of their first holes.
std::vector<std::vector<uint32_t>> hole_groups(const std::vector<std::vector<uint32_t>>& loops) {
  std::vector<uint32_t> group(loops.size());
  for (uint32_t i = 0; i < group.size(); ++i) group[i] = i;
  const auto root = [&](uint32_t i) {
    while (group[i] != i) i = group[i] = group[group[i]];
    return i;
  };
  std::unordered_map<uint32_t, uint32_t> hole_at;  // vertex -> the first hole through it
  for (uint32_t i = 0; i < loops.size(); ++i)
    for (uint32_t v : loops[i]) {
      const auto [it, first] = hole_at.emplace(v, i);
      if (first) continue;
      const uint32_t a = root(it->second), b = root(i);
      group[std::max(a, b)] = std::min(a, b);
    }
  std::vector<std::vector<uint32_t>> groups;
  std::unordered_map<uint32_t, size_t> slot;  // root -> its group
  for (uint32_t i = 0; i < loops.size(); ++i) {
    const auto [it, fresh] = slot.emplace(root(i), groups.size());
    if (fresh) groups.emplace_back();
    groups[it->second].push_back(i);
  }
  return groups;
}

// The patch of one loop, its new vertices numbered from `first`; null when the hole
// is skipped (too many edges, or a fill larger than the limit).
std::unique_ptr<HolePatch> make_patch(const TriangleMesh& mesh, const HalfEdges& he, const std::vector<uint32_t>& loop,
                                      const AddedEdges& added_edges, uint32_t first, const HoleFillOptions& options) {
  if (options.max_hole_edges && loop.size() > options.max_hole_edges) return nullptr;
  // The fill walks the loop backwards: each patch triangle uses a loop edge in the
  // direction opposite to the mesh triangle beside it.
  const std::vector<uint32_t> poly(loop.rbegin(), loop.rend());
  std::vector<Vec3f> edge_normal(poly.size());
  for (size_t k = 0; k < poly.size(); ++k) {
    const long t = he.find(poly[(k + 1) % poly.size()], poly[k]);
    edge_normal[k] = Vec3f::Zero();
    if (t >= 0) {
      const Triangle& tri = mesh.triangles[static_cast<size_t>(t)];
      edge_normal[k] = unit_normal(mesh.vertices[tri[0]], mesh.vertices[tri[1]], mesh.vertices[tri[2]]);
    }
  }
  auto patch = std::make_unique<HolePatch>(mesh, he, added_edges, first);
  patch->triangulate(poly, edge_normal, std::max<size_t>(options.max_dp_edges, 4));
  if (options.max_hole_area > 0.0 && patch->area() > options.max_hole_area) return nullptr;
  if (options.refine) patch->refine();
  if (options.fairing != HoleFairing::kNone) patch->fair(loop, options.fairing == HoleFairing::kThinPlate);
  return patch;
}

// The patches of one group's holes, one after the other (each may not create an
// edge an earlier one made), their new vertices numbered on from `first`:
// (*patches)[i] for hole i, numbered from (*first_of)[i].
void fill_group(const TriangleMesh& mesh, const HalfEdges& he, const std::vector<std::vector<uint32_t>>& loops,
                const std::vector<uint32_t>& group, uint32_t first, const HoleFillOptions& options,
                std::vector<std::unique_ptr<HolePatch>>* patches, std::vector<uint32_t>* first_of) {
  AddedEdges added_edges;
  uint32_t next = first;
  for (const uint32_t i : group) {
    std::unique_ptr<HolePatch> patch = make_patch(mesh, he, loops[i], added_edges, next, options);
    if (!patch) continue;
    for (const Triangle& t : patch->triangles())
      for (int k = 0; k < 3; ++k) added_edges.insert(t[k], t[(k + 1) % 3]);
    (*first_of)[i] = next;
    next += static_cast<uint32_t>(patch->new_vertices().size());
    (*patches)[i] = std::move(patch);
  }
}

}  // namespace

HoleFillStats fill_holes(TriangleMesh& mesh, const HoleFillOptions& options) {
  HoleFillStats stats;
  const size_t original_vertices = mesh.vertices.size();
  if (mesh.confidence.empty()) mesh.confidence.assign(original_vertices, 1.f);
  const HalfEdges he(mesh);
  const std::vector<std::vector<uint32_t>> loops = boundary_loops(boundary_edges(he));
  stats.holes = loops.size();
  if (loops.empty()) return stats;
  for (const std::vector<uint32_t>& loop : loops)
    stats.largest_hole_edges = std::max(stats.largest_hole_edges, loop.size());

  // A patch may not create an edge another patch made, so holes that share a
  // vertex are filled one after the other, in loop order (hole_groups). Groups
  // touch nothing in common, so they are filled side by side, each numbering its
  // patches' new vertices from the mesh's vertex count on; the patches are then
  // appended in loop order, their vertices renumbered: the same mesh, vertex for
  // vertex, as filling every hole in turn. (A patch's triangles use its loop's
  // vertices and its own new ones only.)
  const std::vector<std::vector<uint32_t>> groups = hole_groups(loops);
  const auto first_apart = static_cast<uint32_t>(original_vertices);
  std::vector<std::unique_ptr<HolePatch>> patches(loops.size());  // null: skipped
  std::vector<uint32_t> first_of(loops.size(), first_apart);      // where each patch numbered from
  tbb::parallel_for(size_t{0}, groups.size(), [&](size_t g) {
    fill_group(mesh, he, loops, groups[g], first_apart, options, &patches, &first_of);
  });

  std::vector<Triangle> added_triangles;
  for (size_t i = 0; i < loops.size(); ++i) {
    if (!patches[i]) continue;
    const HolePatch& patch = *patches[i];
    const auto first = static_cast<uint32_t>(mesh.vertices.size());
    stats.area_added += patch.area();
    for (Triangle t : patch.triangles()) {
      for (uint32_t& v : t)
        if (v >= first_apart) v = v - first_of[i] + first;
      added_triangles.push_back(t);
    }
    mesh.vertices.insert(mesh.vertices.end(), patch.new_vertices().begin(), patch.new_vertices().end());
    ++stats.holes_filled;
  }
  stats.triangles_added = added_triangles.size();
  stats.vertices_added = mesh.vertices.size() - original_vertices;
  mesh.triangles.insert(mesh.triangles.end(), added_triangles.begin(), added_triangles.end());
  mesh.confidence.resize(mesh.vertices.size(), 0.f);
  if (!mesh.normals.empty()) {
    // The patches' new vertices have none yet: the mesh is whole again only once
    // its normals are recomputed over every vertex.
    mesh.normals.clear();
    mesh.normals = compute_vertex_normals(mesh);
  }
  return stats;
}

size_t trim_boundary_flaps(TriangleMesh& mesh, const std::function<bool(uint32_t vertex)>& unsupported) {
  const HalfEdges he(mesh);  // its rows also list the triangles around each vertex
  const std::vector<BoundaryEdge> boundary = boundary_edges(he);
  if (boundary.empty()) return 0;
  const size_t nv = mesh.vertices.size(), nt = mesh.triangles.size();
  std::vector<uint8_t> alive(nt, 1);
  std::vector<int8_t> cache(nv, -1);
  auto is_unsupported = [&](uint32_t v) {
    if (cache[v] < 0) cache[v] = unsupported(v) ? 1 : 0;
    return cache[v] == 1;
  };
  auto has_half_edge = [&](uint32_t a, uint32_t b) {  // an alive triangle walks a -> b
    for (size_t s = he.start[a]; s < he.start[a + 1]; ++s)
      if (he.to[s] == b && alive[he.triangle[s]]) return true;
    return false;
  };
  auto on_boundary = [&](uint32_t t) {
    const Triangle& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k)
      if (!has_half_edge(tri[(k + 1) % 3], tri[k])) return true;
    return false;
  };
  std::vector<uint32_t> queue;
  for (const BoundaryEdge& e : boundary) queue.push_back(e.triangle);
  size_t removed = 0;
  while (!queue.empty()) {
    const uint32_t t = queue.back();
    queue.pop_back();
    if (!alive[t]) continue;
    const Triangle& tri = mesh.triangles[t];
    if (!is_unsupported(tri[0]) || !is_unsupported(tri[1]) || !is_unsupported(tri[2])) continue;
    if (!on_boundary(t)) continue;
    alive[t] = 0;
    ++removed;
    for (uint32_t v : tri)
      for (size_t s = he.start[v]; s < he.start[v + 1]; ++s)
        if (alive[he.triangle[s]]) queue.push_back(he.triangle[s]);
  }
  if (removed == 0) return 0;
  size_t out = 0;
  for (size_t i = 0; i < nt; ++i)
    if (alive[i]) mesh.triangles[out++] = mesh.triangles[i];
  mesh.triangles.resize(out);
  remove_unreferenced_vertices(mesh);
  return removed;
}

}  // namespace bodyscan
