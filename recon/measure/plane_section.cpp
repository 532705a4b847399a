#include "recon/measure/plane_section.hpp"

#include <algorithm>
#include <limits>

namespace bodyscan {

namespace {

uint64_t edge_key(uint32_t a, uint32_t b) {
  if (a > b) std::swap(a, b);
  return (static_cast<uint64_t>(a) << 32) | b;
}

}  // namespace

std::vector<SectionLoop> plane_section(const TriangleMesh& mesh, const Plane& plane) {
  return plane_section(mesh, plane, nullptr);
}

std::vector<SectionLoop> plane_section(const TriangleMesh& mesh, const Plane& plane,
                                       const std::vector<uint32_t>* triangles) {
  const size_t nv = mesh.vertices.size();
  // In plain doubles: this runs for every vertex of every cut, and the sanitizers'
  // build does not inline Eigen's small expressions.
  const double nx = plane.normal.x(), ny = plane.normal.y(), nz = plane.normal.z();
  const double px = plane.point.x(), py = plane.point.y(), pz = plane.point.z();
  auto dist = [&](uint32_t i) {
    const Vec3f& v = mesh.vertices[i];
    const double x = nx * (v.x() - px) + ny * (v.y() - py) + nz * (v.z() - pz);
    return x == 0 ? 1e-12 : x;  // on the plane: a hair on the positive side
  };
  // Each crossed triangle gives one segment between two crossed edges. Link the
  // segments through their shared edges: an edge of a manifold mesh is crossed by
  // the segments of its (at most) two triangles.
  struct Segment {
    uint64_t a, b;
  };
  std::vector<Segment> segments;
  std::vector<std::pair<uint64_t, uint32_t>> by_edge;  // (edge, segment), sorted by edge
  const size_t count = triangles ? triangles->size() : mesh.triangles.size();
  for (size_t ti = 0; ti < count; ++ti) {
    const Triangle& t = mesh.triangles[triangles ? (*triangles)[ti] : ti];
    const double dt[3] = {dist(t[0]), dist(t[1]), dist(t[2])};
    uint64_t crossed[2];
    int n = 0;
    for (int k = 0; k < 3; ++k) {
      const uint32_t u = t[k], v = t[(k + 1) % 3];
      if ((dt[k] > 0) != (dt[(k + 1) % 3] > 0) && n < 2) crossed[n++] = edge_key(u, v);
    }
    if (n != 2) continue;
    const auto s = static_cast<uint32_t>(segments.size());
    segments.push_back({crossed[0], crossed[1]});
    by_edge.emplace_back(crossed[0], s);
    by_edge.emplace_back(crossed[1], s);
  }
  std::sort(by_edge.begin(), by_edge.end());
  // The segment across each end of each segment, found once (a search per step of
  // the walk was a sixth of the automatic measurements' time): across[2 s + k] for
  // segments[s]'s edge a (k = 0) or b (k = 1). kNone on the mesh's border; kMany on
  // an edge more than two segments cross (non-manifold), where the walk takes any
  // unused one.
  constexpr uint32_t kNone = 0xffffffffu, kMany = 0xfffffffeu;
  std::vector<uint32_t> across(2 * segments.size(), kNone);
  auto slot = [&](uint32_t seg, uint64_t edge) { return 2 * size_t{seg} + (segments[seg].a == edge ? 0 : 1); };
  std::vector<std::pair<uint64_t, uint32_t>> starts;  // (border edge, its segment): open polylines begin there
  for (size_t i = 0; i < by_edge.size();) {
    size_t j = i + 1;
    while (j < by_edge.size() && by_edge[j].first == by_edge[i].first) ++j;
    const uint64_t edge = by_edge[i].first;
    if (j - i == 1) {
      starts.push_back(by_edge[i]);
    } else if (j - i == 2) {
      across[slot(by_edge[i].second, edge)] = by_edge[i + 1].second;
      across[slot(by_edge[i + 1].second, edge)] = by_edge[i].second;
    } else {
      for (size_t k = i; k < j; ++k) across[slot(by_edge[k].second, edge)] = kMany;
    }
    i = j;
  }
  auto point_on = [&](uint64_t key, float* confidence) {
    const auto a = static_cast<uint32_t>(key >> 32), b = static_cast<uint32_t>(key & 0xffffffffu);
    const double da = dist(a), db = dist(b);
    const double t = da / (da - db);
    if (confidence) {
      *confidence = mesh.confidence.size() == nv
                        ? static_cast<float>((1 - t) * mesh.confidence[a] + t * mesh.confidence[b])
                        : 1.f;
    }
    return ((1 - t) * mesh.vertices[a].cast<double>() + t * mesh.vertices[b].cast<double>()).eval();
  };
  std::vector<uint8_t> used(segments.size(), 0);
  std::vector<SectionLoop> loops;
  // Open polylines first (from an edge only one segment uses), then closed loops.
  auto walk = [&](uint32_t s, const uint64_t start_edge) {
    SectionLoop loop;
    loop.closed = false;
    float c = 1;
    loop.points.push_back(point_on(start_edge, &c));
    loop.confidence.push_back(c);
    uint64_t edge = start_edge;
    for (;;) {
      used[s] = 1;
      const bool leave_by_b = segments[s].a == edge;
      edge = leave_by_b ? segments[s].b : segments[s].a;
      if (edge == start_edge) {
        loop.closed = true;
        break;
      }
      loop.points.push_back(point_on(edge, &c));
      loop.confidence.push_back(c);
      uint32_t next = across[2 * size_t{s} + (leave_by_b ? 1 : 0)];
      if (next == kMany) {
        next = kNone;
        for (auto it = std::lower_bound(by_edge.begin(), by_edge.end(), std::make_pair(edge, uint32_t{0}));
             it != by_edge.end() && it->first == edge; ++it)
          if (!used[it->second]) next = it->second;
      }
      if (next == kNone || used[next]) break;  // the mesh's border (or a non-manifold dead end)
      s = next;
    }
    if (loop.points.size() >= 3) loops.push_back(std::move(loop));
  };
  for (const auto& [edge, seg] : starts)
    if (!used[seg]) walk(seg, edge);
  for (uint32_t s = 0; s < segments.size(); ++s)
    if (!used[s]) walk(s, segments[s].a);
  return loops;
}

std::vector<std::vector<uint32_t>> triangles_by_plane(const TriangleMesh& mesh, const std::vector<uint32_t>& candidates,
                                                      const Eigen::Vector3d& origin, const Eigen::Vector3d& normal,
                                                      const std::vector<double>& offsets) {
  std::vector<std::vector<uint32_t>> out(offsets.size());
  // A plane's own distances (plane_section) round differently from these
  // projections minus its offset by far less than this: a triangle within it of a
  // plane is listed, and plane_section decides whether it crosses.
  constexpr double kMarginMm = 1e-6;
  for (const uint32_t t : candidates) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const uint32_t v : mesh.triangles[t]) {
      const double d = normal.dot(mesh.vertices[v].cast<double>() - origin);
      lo = std::min(lo, d), hi = std::max(hi, d);
    }
    auto k = static_cast<size_t>(std::lower_bound(offsets.begin(), offsets.end(), lo - kMarginMm) - offsets.begin());
    for (; k < offsets.size() && offsets[k] <= hi + kMarginMm; ++k) out[k].push_back(t);
  }
  return out;
}

}  // namespace bodyscan
