#include "recon/geometry/triangle_mesh.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cassert>
#include <numeric>

namespace bodyscan {

bool TriangleMesh::is_consistent() const {
  if (!normals.empty() && normals.size() != vertices.size()) return false;
  if (!confidence.empty() && confidence.size() != vertices.size()) return false;
  const size_t n = vertices.size();
  for (const Triangle& t : triangles) {
    if (t[0] >= n || t[1] >= n || t[2] >= n) return false;
  }
  return true;
}

namespace {

bool is_degenerate(const Triangle& t) { return t[0] == t[1] || t[1] == t[2] || t[2] == t[0]; }

// Union-find with path halving and union by size; triangles are the nodes.
class DisjointSets {
 public:
  explicit DisjointSets(size_t n) : parent_(n), size_(n, 1) { std::iota(parent_.begin(), parent_.end(), uint32_t{0}); }
  uint32_t find(uint32_t x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }
  void unite(uint32_t a, uint32_t b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (size_[a] < size_[b]) std::swap(a, b);
    parent_[b] = a;
    size_[a] += size_[b];
  }

 private:
  std::vector<uint32_t> parent_;
  std::vector<uint32_t> size_;
};

// One directed use of an undirected edge {lo, hi}, filed under lo.
struct EdgeUse {
  uint32_t hi;
  uint32_t triangle;
  bool lo_to_hi;  // the triangle walks the edge from lo to hi
};

}  // namespace

MeshTopology analyze_topology(const TriangleMesh& mesh) {
  assert(mesh.is_consistent());
  MeshTopology topo;
  const size_t num_vertices = mesh.vertices.size();
  const size_t num_triangles = mesh.triangles.size();

  // Degenerate triangles have no proper edges and no area: they are counted, then
  // left out of edges, faces, referenced vertices and components.
  std::vector<uint8_t> referenced(num_vertices, 0);
  size_t proper_triangles = 0;
  // Edges are bucketed by their smaller vertex (a counting sort), so the edge map
  // costs O(F) rather than a global sort of 3F keys; buckets are then tiny.
  std::vector<size_t> bucket_start(num_vertices + 1, 0);
  for (const Triangle& t : mesh.triangles) {
    if (is_degenerate(t)) {
      ++topo.degenerate_triangles;
      continue;
    }
    ++proper_triangles;
    for (int k = 0; k < 3; ++k) {
      referenced[t[k]] = 1;
      ++bucket_start[std::min(t[k], t[(k + 1) % 3]) + 1];
    }
  }
  std::partial_sum(bucket_start.begin(), bucket_start.end(), bucket_start.begin());

  std::vector<EdgeUse> uses(bucket_start.back());
  std::vector<size_t> fill(bucket_start.begin(), bucket_start.end() - 1);
  for (size_t i = 0; i < num_triangles; ++i) {
    const Triangle& t = mesh.triangles[i];
    if (is_degenerate(t)) continue;
    for (int k = 0; k < 3; ++k) {
      const uint32_t from = t[k], to = t[(k + 1) % 3];
      const uint32_t lo = std::min(from, to), hi = std::max(from, to);
      uses[fill[lo]++] = {hi, static_cast<uint32_t>(i), from == lo};
    }
  }

  DisjointSets sets(num_triangles);
  size_t num_edges = 0;
  for (size_t v = 0; v < num_vertices; ++v) {
    EdgeUse* begin = uses.data() + bucket_start[v];
    EdgeUse* end = uses.data() + bucket_start[v + 1];
    std::sort(begin, end, [](const EdgeUse& a, const EdgeUse& b) { return a.hi < b.hi; });
    for (EdgeUse* run = begin; run != end;) {
      EdgeUse* run_end = run + 1;
      while (run_end != end && run_end->hi == run->hi) ++run_end;
      const size_t count = static_cast<size_t>(run_end - run);
      ++num_edges;
      if (count == 1) {
        ++topo.boundary_edges;
      } else if (count > 2) {
        ++topo.non_manifold_edges;
      } else if (run[0].lo_to_hi == run[1].lo_to_hi) {
        // Two consistently wound neighbours walk their shared edge in opposite directions.
        ++topo.inconsistent_edges;
      }
      for (EdgeUse* e = run + 1; e != run_end; ++e) sets.unite(run->triangle, e->triangle);
      run = run_end;
    }
  }

  for (size_t i = 0; i < num_triangles; ++i) {
    if (!is_degenerate(mesh.triangles[i]) && sets.find(static_cast<uint32_t>(i)) == i) {
      ++topo.components;
    }
  }
  const size_t num_referenced = static_cast<size_t>(std::count(referenced.begin(), referenced.end(), uint8_t{1}));
  topo.unreferenced_vertices = num_vertices - num_referenced;
  topo.euler_characteristic =
      static_cast<long>(num_referenced) - static_cast<long>(num_edges) + static_cast<long>(proper_triangles);
  return topo;
}

std::vector<Vec3f> compute_vertex_normals(const TriangleMesh& mesh) {
  assert(mesh.is_consistent());
  // The unnormalised cross product is twice the triangle's area along its normal,
  // so summing it weights each face by area. Doubles keep tiny faces next to big
  // ones from being lost.
  std::vector<Vec3d> sum(mesh.vertices.size(), Vec3d::Zero());
  for (const Triangle& t : mesh.triangles) {
    const Vec3d a = mesh.vertices[t[0]].cast<double>();
    const Vec3d b = mesh.vertices[t[1]].cast<double>();
    const Vec3d c = mesh.vertices[t[2]].cast<double>();
    const Vec3d n = (b - a).cross(c - a);
    sum[t[0]] += n;
    sum[t[1]] += n;
    sum[t[2]] += n;
  }
  std::vector<Vec3f> normals(mesh.vertices.size());
  for (size_t i = 0; i < sum.size(); ++i) {
    const double len = sum[i].norm();
    // Vertices without area around them (unreferenced, or only on degenerate
    // faces) have no direction: zero says so rather than inventing one.
    normals[i] = len > 0.0 ? Vec3f((sum[i] / len).cast<float>()) : Vec3f::Zero();
  }
  return normals;
}

double signed_volume(const TriangleMesh& mesh) {
  assert(mesh.is_consistent());
  if (mesh.triangles.empty()) return 0.0;
  // Sum of tetrahedra from a reference point to each face. Any reference gives the
  // same result for a closed mesh; one on the mesh keeps the terms small, so a body
  // far from the origin loses no precision to cancellation.
  const Vec3d origin = mesh.vertices[mesh.triangles[0][0]].cast<double>();
  double six_volume = 0.0;
  for (const Triangle& t : mesh.triangles) {
    const Vec3d a = mesh.vertices[t[0]].cast<double>() - origin;
    const Vec3d b = mesh.vertices[t[1]].cast<double>() - origin;
    const Vec3d c = mesh.vertices[t[2]].cast<double>() - origin;
    six_volume += a.dot(b.cross(c));
  }
  return six_volume / 6.0;
}

double surface_area(const TriangleMesh& mesh) {
  assert(mesh.is_consistent());
  double twice_area = 0.0;
  for (const Triangle& t : mesh.triangles) {
    const Vec3d a = mesh.vertices[t[0]].cast<double>();
    const Vec3d b = mesh.vertices[t[1]].cast<double>();
    const Vec3d c = mesh.vertices[t[2]].cast<double>();
    twice_area += (b - a).cross(c - a).norm();
  }
  return twice_area / 2.0;
}

}  // namespace bodyscan
