#include "recon/geometry/mesh_components.hpp"

#include <algorithm>
#include <numeric>

namespace bodyscan {

namespace {
uint32_t find_root(std::vector<uint32_t>& parent, uint32_t x) {
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];
    x = parent[x];
  }
  return x;
}
}  // namespace

MeshComponents label_components(const TriangleMesh& mesh) {
  MeshComponents c;
  const size_t nv = mesh.vertices.size(), nt = mesh.triangles.size();
  // Each vertex's triangles (counting sort), to find the triangles across each edge.
  std::vector<uint32_t> first(nv + 1, 0), around(3 * nt);
  for (const Triangle& t : mesh.triangles)
    for (uint32_t v : t) ++first[v + 1];
  std::partial_sum(first.begin(), first.end(), first.begin());
  std::vector<uint32_t> fill(first.begin(), first.end() - 1);
  for (size_t i = 0; i < nt; ++i)
    for (uint32_t v : mesh.triangles[i]) around[fill[v]++] = static_cast<uint32_t>(i);
  std::vector<uint32_t> parent(nt);
  std::iota(parent.begin(), parent.end(), 0u);
  for (size_t i = 0; i < nt; ++i) {
    const Triangle& t = mesh.triangles[i];
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = t[k], b = t[(k + 1) % 3];
      for (uint32_t j = first[a]; j < first[a + 1]; ++j) {
        const Triangle& o = mesh.triangles[around[j]];
        if (around[j] == i || (o[0] != b && o[1] != b && o[2] != b)) continue;
        const uint32_t ra = find_root(parent, static_cast<uint32_t>(i)), rb = find_root(parent, around[j]);
        if (ra != rb) parent[rb] = ra;
      }
    }
  }
  // Count triangles per root, then number roots by decreasing size.
  std::vector<size_t> count(nt, 0);
  c.triangle_label.resize(nt);
  for (size_t i = 0; i < nt; ++i) {
    c.triangle_label[i] = find_root(parent, static_cast<uint32_t>(i));
    ++count[c.triangle_label[i]];
  }
  std::vector<uint32_t> roots;
  for (uint32_t v = 0; v < nt; ++v)
    if (count[v] > 0) roots.push_back(v);
  std::stable_sort(roots.begin(), roots.end(), [&](uint32_t a, uint32_t b) { return count[a] > count[b]; });
  std::vector<uint32_t> rank(nt, 0);
  for (size_t r = 0; r < roots.size(); ++r) {
    rank[roots[r]] = static_cast<uint32_t>(r);
    c.triangle_count.push_back(count[roots[r]]);
  }
  for (uint32_t& l : c.triangle_label) l = rank[l];
  return c;
}

void remove_unreferenced_vertices(TriangleMesh& mesh) {
  std::vector<uint32_t> remap(mesh.vertices.size(), UINT32_MAX);
  for (const Triangle& t : mesh.triangles)
    for (uint32_t v : t) remap[v] = 0;
  uint32_t next = 0;
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (remap[v] == UINT32_MAX) continue;
    remap[v] = next;
    mesh.vertices[next] = mesh.vertices[v];
    if (!mesh.normals.empty()) mesh.normals[next] = mesh.normals[v];
    if (!mesh.confidence.empty()) mesh.confidence[next] = mesh.confidence[v];
    ++next;
  }
  mesh.vertices.resize(next);
  if (!mesh.normals.empty()) mesh.normals.resize(next);
  if (!mesh.confidence.empty()) mesh.confidence.resize(next);
  for (Triangle& t : mesh.triangles)
    for (uint32_t& v : t) v = remap[v];
}

size_t remove_small_components(TriangleMesh& mesh, double min_fraction) {
  if (mesh.triangles.empty()) return 0;
  const MeshComponents c = label_components(mesh);
  const double threshold = min_fraction * static_cast<double>(c.triangle_count[0]);
  size_t removed = 0;
  for (size_t count : c.triangle_count)
    if (static_cast<double>(count) < threshold) ++removed;
  if (removed == 0) return 0;
  size_t out = 0;
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    if (static_cast<double>(c.triangle_count[c.triangle_label[i]]) < threshold) continue;
    mesh.triangles[out++] = mesh.triangles[i];
  }
  mesh.triangles.resize(out);
  remove_unreferenced_vertices(mesh);
  return removed;
}

}  // namespace bodyscan
