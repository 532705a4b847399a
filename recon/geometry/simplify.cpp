#include "recon/geometry/simplify.hpp"

#include <meshoptimizer.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <tuple>

#include "recon/geometry/fill_holes.hpp"
#include "recon/geometry/mesh_components.hpp"
#include "recon/geometry/mesh_distance.hpp"

namespace bodyscan {

namespace {

// The largest distance from a vertex of `from` to the surface `to`.
double largest_vertex_distance(const TriangleMesh& from, const TriangleMesh& to) {
  const MeshDistance distance(to);
  std::atomic<float> largest{0};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, from.vertices.size(), 4096), [&](const auto& r) {
    float local = 0;
    for (size_t i = r.begin(); i < r.end(); ++i)
      local = std::max(local, distance.closest_point(from.vertices[i]).distance);
    float seen = largest.load();
    while (local > seen && !largest.compare_exchange_weak(seen, local)) {
    }
  });
  return largest.load();
}

// Collapses where the surface is thin (fingers, a fold) can leave a fin: two
// triangles on the same three corners, facing opposite ways, which bound nothing
// and make their edges non-manifold. Removes every such pair (indices in place).
void drop_fins(std::vector<unsigned int>* indices) {
  std::vector<unsigned int>& ix = *indices;
  const size_t n = ix.size() / 3;
  std::vector<std::pair<std::array<unsigned int, 3>, size_t>> sorted(n);
  for (size_t t = 0; t < n; ++t) {
    std::array<unsigned int, 3> k = {ix[3 * t], ix[3 * t + 1], ix[3 * t + 2]};
    std::sort(k.begin(), k.end());
    sorted[t] = {k, t};
  }
  std::sort(sorted.begin(), sorted.end());
  std::vector<char> drop(n, 0);
  for (size_t i = 0; i + 1 < n; ++i) {
    if (sorted[i].first != sorted[i + 1].first) continue;
    drop[sorted[i].second] = drop[sorted[i + 1].second] = 1;
    ++i;  // a pair; a third copy pairs with a fourth or stays
  }
  size_t out = 0;
  for (size_t t = 0; t < n; ++t)
    if (!drop[t])
      for (int k = 0; k < 3; ++k) ix[out++] = ix[3 * t + k];
  ix.resize(out);
}

// Collapses can also pinch two parts of the surface together along an edge
// (fingers, thighs close together), leaving it shared by four triangles. Opens
// the surface round every such edge (the triangles touching either end) and
// closes the holes again (fill_holes: Liepa's minimal-dihedral patch, faired, not
// refined). False when edges stay non-manifold.
bool unpinch(TriangleMesh* mesh) {
  for (int round = 0; round < 3; ++round) {
    std::vector<std::pair<uint64_t, uint32_t>> edges;
    edges.reserve(3 * mesh->num_triangles());
    for (uint32_t t = 0; t < mesh->num_triangles(); ++t)
      for (int k = 0; k < 3; ++k) {
        const uint32_t a = mesh->triangles[t][k], b = mesh->triangles[t][(k + 1) % 3];
        edges.push_back({(uint64_t{std::min(a, b)} << 32) | std::max(a, b), t});
      }
    std::sort(edges.begin(), edges.end());
    std::vector<char> open(mesh->num_vertices(), 0);
    bool pinched = false;
    for (size_t i = 0, j = 0; i < edges.size(); i = j) {
      for (j = i; j < edges.size() && edges[j].first == edges[i].first; ++j) {
      }
      if (j - i > 2) {
        pinched = true;
        open[edges[i].first >> 32] = open[edges[i].first & 0xffffffffu] = 1;
      }
    }
    if (!pinched) return true;
    std::vector<Triangle> kept;
    kept.reserve(mesh->num_triangles());
    for (const Triangle& t : mesh->triangles)
      if (!open[t[0]] && !open[t[1]] && !open[t[2]]) kept.push_back(t);
    mesh->triangles = std::move(kept);
    HoleFillOptions fill;
    fill.refine = false;  // the budget stands
    fill_holes(*mesh, fill);
  }
  return analyze_topology(*mesh).non_manifold_edges == 0;
}

// Marching cubes leaves vertices within a hair of each other where the surface
// passes through a grid node. Written in metres they can print the same, and an
// importer that joins vertices by position (most CAD tools) would then make
// non-manifold edges of them. Vertices within kWeldMm are joined (to the first of
// them), the triangles that flattens dropped, and unused vertices left out.
constexpr float kWeldMm = 1e-3f;

TriangleMesh welded(const TriangleMesh& mesh) {
  // In (X, Y, Z) order, each vertex against those after it within kWeldMm in X;
  // a pair within kWeldMm joins, to the lower index (union-find). A surface from
  // a grid has thousands of vertices on one X: past kWeldMm in Y the rest of
  // that X is skipped.
  const std::vector<Vec3f>& v = mesh.vertices;
  const size_t n = v.size();
  std::vector<uint32_t> order(n), to(n);
  for (uint32_t i = 0; i < n; ++i) order[i] = to[i] = i;
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return std::tie(v[a].x(), v[a].y(), v[a].z()) < std::tie(v[b].x(), v[b].y(), v[b].z());
  });
  std::vector<size_t> next_x(n + 1, n);  // the first place in `order` past this one's X
  for (size_t a = n; a-- > 0;) next_x[a] = a + 1 < n && v[order[a + 1]].x() == v[order[a]].x() ? next_x[a + 1] : a + 1;
  const auto root = [&](uint32_t i) {
    while (to[i] != i) i = to[i] = to[to[i]];
    return i;
  };
  for (size_t a = 0; a < n; ++a) {
    const Vec3f& p = v[order[a]];
    for (size_t b = a + 1; b < n && v[order[b]].x() - p.x() <= kWeldMm;) {
      const Vec3f& q = v[order[b]];
      if (q.y() - p.y() > kWeldMm) {
        b = next_x[b];
        continue;
      }
      if ((q - p).norm() <= kWeldMm) {
        const uint32_t ra = root(order[a]), rb = root(order[b]);
        to[std::max(ra, rb)] = std::min(ra, rb);
      }
      ++b;
    }
  }
  for (uint32_t i = 0; i < n; ++i) to[i] = root(i);
  TriangleMesh out;
  out.vertices = mesh.vertices;
  out.triangles.reserve(mesh.num_triangles());
  for (const Triangle& t : mesh.triangles) {
    const Triangle w = {to[t[0]], to[t[1]], to[t[2]]};
    if (w[0] != w[1] && w[1] != w[2] && w[0] != w[2]) out.triangles.push_back(w);
  }
  remove_unreferenced_vertices(out);
  return out;
}

}  // namespace

StatusOr<SimplifyResult> simplify(const TriangleMesh& mesh, const SimplifyOptions& options) {
  if (!mesh.is_consistent()) return invalid_argument("simplify: the mesh's indices or attributes are inconsistent");
  if (options.max_triangles < 4) return invalid_argument("simplify: a budget of at least 4 triangles");
  if (options.max_error_mm < 0) return invalid_argument("simplify: the error bound is a distance, 0 or more");
  SimplifyResult out;
  const TriangleMesh source = welded(mesh);
  if (source.num_triangles() <= options.max_triangles) {
    out.mesh = source;
    out.mesh.normals = compute_vertex_normals(out.mesh);
    return out;
  }
  std::vector<unsigned int> indices(3 * source.num_triangles());
  for (size_t t = 0; t < source.num_triangles(); ++t)
    for (int k = 0; k < 3; ++k) indices[3 * t + k] = source.triangles[t][k];
  const float* positions = source.vertices.front().data();
  const size_t stride = sizeof(Vec3f);
  // meshoptimizer's errors are relative to the mesh's extent.
  const float scale = meshopt_simplifyScale(positions, source.num_vertices(), stride);
  const float target_error = options.max_error_mm > 0 && scale > 0 ? static_cast<float>(options.max_error_mm / scale)
                                                                   : std::numeric_limits<float>::max();
  std::vector<unsigned int> kept(indices.size());
  float relative_error = 0;
  kept.resize(meshopt_simplify(kept.data(), indices.data(), indices.size(), positions, source.num_vertices(), stride,
                               3 * options.max_triangles, target_error, 0, &relative_error));
  drop_fins(&kept);
  if (kept.size() < 3) return internal_error("simplify: nothing of the surface was left");
  // Only the vertices the triangles still use, in the order they are first used.
  std::vector<unsigned int> remap(source.num_vertices());
  const size_t n = meshopt_optimizeVertexFetchRemap(remap.data(), kept.data(), kept.size(), source.num_vertices());
  out.mesh.vertices.resize(n);
  for (size_t v = 0; v < source.num_vertices(); ++v)
    if (remap[v] != ~0u) out.mesh.vertices[remap[v]] = source.vertices[v];
  out.mesh.triangles.resize(kept.size() / 3);
  for (size_t t = 0; t < out.mesh.triangles.size(); ++t)
    out.mesh.triangles[t] = {remap[kept[3 * t]], remap[kept[3 * t + 1]], remap[kept[3 * t + 2]]};
  unpinch(&out.mesh);
  out.mesh.confidence.clear();
  // Scraps the collapses and the repair closed off on their own (a fin's two
  // triangles, a sliver): a ten-thousandth of the body or less. A pinched-off
  // fingertip stays, a closed piece touching the hand at a corner.
  remove_small_components(out.mesh, 1e-4);
  remove_unreferenced_vertices(out.mesh);  // the repair's opened corners
  out.mesh.normals = compute_vertex_normals(out.mesh);
  if (options.measure_deviation)
    out.max_deviation_mm = std::max(largest_vertex_distance(mesh, out.mesh), largest_vertex_distance(out.mesh, mesh));
  return out;
}

}  // namespace bodyscan
