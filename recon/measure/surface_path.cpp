#include "recon/measure/surface_path.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

#include "recon/geometry/mesh_distance.hpp"
#include "recon/measure/fill_bound.hpp"

namespace bodyscan {

namespace {

constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

double angle_between(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const double n = a.norm() * b.norm();
  if (n <= 0) return 0;
  return std::acos(std::clamp(a.dot(b) / n, -1.0, 1.0));
}

// A strip triangle laid flat: its corners' plane positions, in the mesh's corner order.
struct Flat {
  uint32_t tri;
  std::array<Eigen::Vector2d, 3> p;
};

// Where two consecutive strip triangles meet, as the path crosses it: the end on the
// traveller's left and on the right (mesh vertices, plane and world positions).
struct Portal {
  uint32_t left = kNone, right = kNone;
  Eigen::Vector2d left2 = Eigen::Vector2d::Zero(), right2 = Eigen::Vector2d::Zero();
};

// A corner of the taut path: the start (portal 0), the end (the last portal) or a
// portal's end it wraps round.
struct Apex {
  size_t portal;
  bool left;
};

// The length of the polyline through the points at every `step` of arc length
// along `path` (and its last point).
double chord_length(const std::vector<Eigen::Vector3d>& path, double step) {
  if (path.size() < 2) return 0;
  double length = 0, carried = 0;  // arc length since the last chord point
  Eigen::Vector3d last = path.front();
  for (size_t i = 1; i < path.size(); ++i) {
    const Eigen::Vector3d a = path[i - 1], b = path[i];
    const double seg = (b - a).norm();
    double at = step - carried;  // where along this segment the next chord point falls
    while (at <= seg) {
      const Eigen::Vector3d p = a + (at / seg) * (b - a);
      length += (p - last).norm();
      last = p;
      at += step;
    }
    carried = seg - (at - step);
  }
  return length + (path.back() - last).norm();
}

}  // namespace

class SurfacePaths::Impl {
 public:
  explicit Impl(const TriangleMesh& mesh) : mesh_(mesh) {
    const size_t nv = mesh.vertices.size(), nt = mesh.triangles.size();
    centroids_.resize(nt);
    double edge_sum = 0;
    for (size_t t = 0; t < nt; ++t) {
      const Triangle& tr = mesh.triangles[t];
      centroids_[t] = (vertex(tr[0]) + vertex(tr[1]) + vertex(tr[2])) / 3.0;
      edge_sum += (vertex(tr[0]) - vertex(tr[1])).norm();
    }
    // Vertices sorted into cubic cells about three edges wide, for snapping.
    cell_ = nt ? std::max(1e-6, 3 * edge_sum / static_cast<double>(nt)) : 1.0;
    cells_.reserve(nv);
    for (uint32_t v = 0; v < nv; ++v) cells_.emplace_back(cell_key(cell_of(vertex(v))), v);
    std::sort(cells_.begin(), cells_.end());
    offset_.assign(nv + 1, 0);
    for (const Triangle& t : mesh.triangles)
      for (uint32_t v : t) ++offset_[v + 1];
    for (size_t v = 0; v < nv; ++v) offset_[v + 1] += offset_[v];
    incident_.resize(offset_[nv]);
    std::vector<uint32_t> fill(offset_.begin(), offset_.end() - 1);
    for (uint32_t t = 0; t < nt; ++t)
      for (uint32_t v : mesh.triangles[t]) incident_[fill[v]++] = t;
    neighbour_.assign(3 * nt, kNone);
    for (uint32_t t = 0; t < nt; ++t)
      for (int i = 0; i < 3; ++i) {
        const uint32_t a = mesh.triangles[t][i], b = mesh.triangles[t][(i + 1) % 3];
        for (uint32_t k = offset_[a]; k < offset_[a + 1]; ++k) {
          const uint32_t u = incident_[k];
          if (u != t && has_edge(u, b, a)) {
            neighbour_[3 * t + i] = u;
            break;
          }
        }
      }
  }

  StatusOr<SurfacePath> find(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                             const SurfacePathOptions& options) const {
    if (mesh_.triangles.empty()) return invalid_argument("the mesh has no triangles");
    SurfacePath out;
    uint32_t ta = 0, tb = 0;
    out.from = snap(from, &ta);
    out.to = snap(to, &tb);
    out.straight_mm = (out.to - out.from).norm();
    std::vector<uint32_t> strip = dual_dijkstra(around(ta, out.from), out.from, around(tb, out.to), out.to);
    if (strip.empty()) {
      return not_found("the two points lie on parts of the surface that do not connect");
    }
    // Each round pulls the strip's path taut and re-routes the strip where that is
    // shorter; a round that does not shorten the path (a vertex it passes straight
    // through, within rounding) ends the search with the best strip so far.
    std::vector<uint32_t> best;
    double best_length = std::numeric_limits<double>::infinity();
    for (size_t round = 0;; ++round) {
      const std::vector<Flat> flat = unfold(strip);
      const std::vector<Portal> portals = make_portals(strip, flat, out.from, out.to);
      const std::vector<Apex> apexes = funnel(portals);
      const double length = taut_length(portals, apexes);
      const bool shorter = length < best_length * (1 - 1e-12);
      if (shorter) {
        best = strip;
        best_length = length;
      }
      if (!shorter || round >= options.max_reroute_rounds || !reroute(strip, flat, portals, apexes, &out.reroutes)) {
        if (!shorter) strip = best;
        const std::vector<Flat> f = shorter ? flat : unfold(strip);
        const std::vector<Portal> p = shorter ? portals : make_portals(strip, f, out.from, out.to);
        trace(strip, p, shorter ? apexes : funnel(p), &out);
        out.path_mm = out.value_mm;
        if (options.tape_step_mm > 0) out.value_mm = chord_length(out.path, options.tape_step_mm);
        return out;
      }
    }
  }

 private:
  bool has_edge(uint32_t t, uint32_t a, uint32_t b) const {
    const Triangle& tr = mesh_.triangles[t];
    for (int i = 0; i < 3; ++i)
      if (tr[i] == a && tr[(i + 1) % 3] == b) return true;
    return false;
  }
  bool has_vertex(uint32_t t, uint32_t v) const {
    const Triangle& tr = mesh_.triangles[t];
    return tr[0] == v || tr[1] == v || tr[2] == v;
  }
  Eigen::Vector3d vertex(uint32_t v) const { return mesh_.vertices[v].cast<double>(); }
  const Eigen::Vector3d& centroid(uint32_t t) const { return centroids_[t]; }

  Eigen::Vector3i cell_of(const Eigen::Vector3d& p) const {
    return Eigen::Vector3i(static_cast<int>(std::floor(p.x() / cell_)), static_cast<int>(std::floor(p.y() / cell_)),
                           static_cast<int>(std::floor(p.z() / cell_)));
  }
  static uint64_t cell_key(const Eigen::Vector3i& c) {
    auto u = [](int x) { return static_cast<uint64_t>(static_cast<uint32_t>(x + (1 << 20))) & 0x1fffffu; };
    return (u(c.x()) << 42) | (u(c.y()) << 21) | u(c.z());
  }

  // The surface point nearest p: the nearest vertex (rings of cells outward), then
  // the nearest point on the triangles round it and round its neighbours.
  Eigen::Vector3d snap(const Eigen::Vector3d& p, uint32_t* triangle) const {
    const Eigen::Vector3i c = cell_of(p);
    uint32_t nearest = 0;
    double best = std::numeric_limits<double>::infinity();
    for (int r = 0; r < (1 << 20); ++r) {
      for (int dx = -r; dx <= r; ++dx)
        for (int dy = -r; dy <= r; ++dy)
          for (int dz = -r; dz <= r; ++dz) {
            if (std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) != r) continue;
            const uint64_t key = cell_key(c + Eigen::Vector3i(dx, dy, dz));
            auto it = std::lower_bound(cells_.begin(), cells_.end(), std::make_pair(key, 0u));
            for (; it != cells_.end() && it->first == key; ++it) {
              const double d = (vertex(it->second) - p).squaredNorm();
              if (d < best) best = d, nearest = it->second;
            }
          }
      if (best <= (r * cell_) * (r * cell_)) break;
      if (r == 16 && !(best < std::numeric_limits<double>::infinity())) {
        // Far from the surface: every vertex, once.
        for (uint32_t v = 0; v < mesh_.vertices.size(); ++v) {
          const double d = (vertex(v) - p).squaredNorm();
          if (d < best) best = d, nearest = v;
        }
        break;
      }
    }
    Eigen::Vector3d out = vertex(nearest);
    double out_d = std::numeric_limits<double>::infinity();
    *triangle = incident_.empty() ? 0 : incident_[offset_[nearest]];
    for (uint32_t k = offset_[nearest]; k < offset_[nearest + 1]; ++k)
      for (uint32_t u : mesh_.triangles[incident_[k]])
        for (uint32_t j = offset_[u]; j < offset_[u + 1]; ++j) {
          const Triangle& tr = mesh_.triangles[incident_[j]];
          const Eigen::Vector3d q = closest_point_on_triangle(p, vertex(tr[0]), vertex(tr[1]), vertex(tr[2]));
          const double d = (q - p).squaredNorm();
          if (d < out_d) out_d = d, out = q, *triangle = incident_[j];
        }
    return out;
  }
  // The corner angle of triangle t at its vertex v (radians).
  double corner_angle(uint32_t t, uint32_t v) const {
    const Triangle& tr = mesh_.triangles[t];
    const int i = tr[0] == v ? 0 : tr[1] == v ? 1 : 2;
    const Eigen::Vector3d p = vertex(v), e1 = vertex(tr[(i + 1) % 3]) - p, e2 = vertex(tr[(i + 2) % 3]) - p;
    const double n = e1.norm() * e2.norm();
    return n > 0 ? std::acos(std::clamp(e1.dot(e2) / n, -1.0, 1.0)) : 0.0;
  }
  // The triangle across t's edge {a, b}, or kNone.
  uint32_t across(uint32_t t, uint32_t a, uint32_t b) const {
    const Triangle& tr = mesh_.triangles[t];
    for (int i = 0; i < 3; ++i) {
      const uint32_t p = tr[i], q = tr[(i + 1) % 3];
      if ((p == a && q == b) || (p == b && q == a)) return neighbour_[3 * t + i];
    }
    return kNone;
  }

  // The triangles that hold surface point p of triangle t: t, and when p lies on a
  // corner or an edge (within rounding), the others round it; the path may leave
  // through any of them.
  std::vector<uint32_t> around(uint32_t t, const Eigen::Vector3d& p) const {
    const Triangle& tr = mesh_.triangles[t];
    double scale = 0;
    for (int i = 0; i < 3; ++i) scale = std::max(scale, (vertex(tr[i]) - vertex(tr[(i + 1) % 3])).norm());
    const double eps = 1e-6 * scale + 1e-9;
    for (uint32_t v : tr)
      if ((vertex(v) - p).norm() <= eps) return {incident_.begin() + offset_[v], incident_.begin() + offset_[v + 1]};
    std::vector<uint32_t> out{t};
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d a = vertex(tr[i]), e = vertex(tr[(i + 1) % 3]) - a;
      const double len2 = e.squaredNorm();
      if (len2 <= 0) continue;
      const double s = std::clamp((p - a).dot(e) / len2, 0.0, 1.0);
      if ((a + s * e - p).norm() <= eps && neighbour_[3 * t + i] != kNone) out.push_back(neighbour_[3 * t + i]);
    }
    return out;
  }

  // Edge-adjacent triangles from one of `starts` (holding point s) to one of `goals`
  // (holding g), by Dijkstra over centroid distances.
  std::vector<uint32_t> dual_dijkstra(const std::vector<uint32_t>& starts, const Eigen::Vector3d& s,
                                      const std::vector<uint32_t>& goals, const Eigen::Vector3d& g) const {
    for (uint32_t t : starts)
      if (std::find(goals.begin(), goals.end(), t) != goals.end()) return {t};
    // A* with the straight distance to g as the (consistent) estimate; the arrays
    // persist between queries and only what a query touched is reset.
    const size_t nt = mesh_.triangles.size();
    if (dist_.size() != nt) {
      dist_.assign(nt, std::numeric_limits<double>::infinity());
      prev_.assign(nt, kNone);
      state_.assign(nt, 0);
    }
    std::vector<uint32_t> touched;
    auto reset = [&] {
      for (uint32_t t : touched) dist_[t] = std::numeric_limits<double>::infinity(), prev_[t] = kNone, state_[t] = 0;
    };
    auto estimate = [&](uint32_t t) { return (centroid(t) - g).norm(); };
    for (uint32_t t : goals) state_[t] |= 1, touched.push_back(t);
    using Item = std::pair<double, uint32_t>;
    std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
    for (uint32_t t : starts) {
      dist_[t] = (centroid(t) - s).norm();
      touched.push_back(t);
      queue.emplace(dist_[t] + estimate(t), t);
    }
    // A goal is reached when popped with its last leg, centroid to g, added (state 2).
    uint32_t reached = kNone;
    while (!queue.empty()) {
      const auto [f, t] = queue.top();
      queue.pop();
      if (state_[t] & 2) {
        reached = t;
        break;
      }
      const double d = dist_[t];
      if (f > d + estimate(t) + 1e-9) continue;
      const Eigen::Vector3d& c = centroid(t);
      if (state_[t] & 1) {
        state_[t] |= 2;
        queue.emplace(d + (c - g).norm(), t);
      }
      for (int i = 0; i < 3; ++i) {
        const uint32_t u = neighbour_[3 * t + i];
        if (u == kNone || (state_[u] & 2)) continue;
        const double du = d + (centroid(u) - c).norm();
        if (du < dist_[u]) {
          if (dist_[u] == std::numeric_limits<double>::infinity() && prev_[u] == kNone) touched.push_back(u);
          dist_[u] = du;
          prev_[u] = t;
          queue.emplace(du + estimate(u), u);
        }
      }
    }
    std::vector<uint32_t> strip;
    if (reached != kNone)
      for (uint32_t t = reached; t != kNone; t = prev_[t]) strip.push_back(t);
    reset();
    std::reverse(strip.begin(), strip.end());
    return strip;
  }

  // Lays the strip flat, each triangle hinged on the edge it shares with the last.
  std::vector<Flat> unfold(const std::vector<uint32_t>& strip) const {
    std::vector<Flat> flat(strip.size());
    {
      const Triangle& t = mesh_.triangles[strip[0]];
      const Eigen::Vector3d a = vertex(t[0]), b = vertex(t[1]), c = vertex(t[2]);
      const double ab = (b - a).norm(), ac = (c - a).norm();
      const double x = ab > 0 ? (b - a).dot(c - a) / ab : 0.0;
      flat[0] = {strip[0],
                 {Eigen::Vector2d(0, 0), Eigen::Vector2d(ab, 0),
                  Eigen::Vector2d(x, std::sqrt(std::max(0.0, ac * ac - x * x)))}};
    }
    for (size_t j = 1; j < strip.size(); ++j) {
      const Triangle& pt = mesh_.triangles[strip[j - 1]];
      const Triangle& t = mesh_.triangles[strip[j]];
      flat[j].tri = strip[j];
      int w = -1;
      Eigen::Vector2d r2 = Eigen::Vector2d::Zero();
      for (int i = 0; i < 3; ++i) {
        int k = -1;
        for (int q = 0; q < 3; ++q)
          if (pt[q] == t[i]) k = q;
        if (k >= 0)
          flat[j].p[i] = flat[j - 1].p[k];
        else
          w = i;
      }
      for (int q = 0; q < 3; ++q)
        if (!has_vertex(strip[j], pt[q])) r2 = flat[j - 1].p[q];
      if (w < 0) {  // the same triangle twice in a row cannot happen; keep it flat
        continue;
      }
      const int iu = (w + 1) % 3, iv = (w + 2) % 3;
      const Eigen::Vector2d u2 = flat[j].p[iu], v2 = flat[j].p[iv];
      const Eigen::Vector2d e = v2 - u2;
      const double len = e.norm();
      const Eigen::Vector3d W = vertex(t[w]);
      const double du = (W - vertex(t[iu])).norm(), dv = (W - vertex(t[iv])).norm();
      if (len <= 0) {
        flat[j].p[w] = u2;
        continue;
      }
      const Eigen::Vector2d ex = e / len, ey(-ex.y(), ex.x());
      const double x = (du * du - dv * dv + len * len) / (2 * len);
      const double y = std::sqrt(std::max(0.0, du * du - x * x));
      const double side = cross2(e, r2 - u2);
      flat[j].p[w] = u2 + x * ex + (side > 0 ? -y : y) * ey;
    }
    return flat;
  }

  Eigen::Vector2d flat_point(const Flat& f, const Eigen::Vector3d& p) const {
    // Barycentric coordinates of p (on the triangle) carried to the flat copy.
    const Triangle& t = mesh_.triangles[f.tri];
    const Eigen::Vector3d a = vertex(t[0]), b = vertex(t[1]), c = vertex(t[2]);
    const Eigen::Vector3d v0 = b - a, v1 = c - a, v2 = p - a;
    const double d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1), d20 = v2.dot(v0), d21 = v2.dot(v1);
    const double den = d00 * d11 - d01 * d01;
    if (den <= 0) return f.p[0];
    const double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
    return (1 - v - w) * f.p[0] + v * f.p[1] + w * f.p[2];
  }

  std::vector<Portal> make_portals(const std::vector<uint32_t>& strip, const std::vector<Flat>& flat,
                                   const Eigen::Vector3d& from, const Eigen::Vector3d& to) const {
    std::vector<Portal> portals(strip.size() + 1);
    const Eigen::Vector2d s2 = flat_point(flat.front(), from), g2 = flat_point(flat.back(), to);
    portals.front().left2 = portals.front().right2 = s2;
    portals.back().left2 = portals.back().right2 = g2;
    for (size_t j = 1; j < strip.size(); ++j) {
      const Triangle& pt = mesh_.triangles[strip[j - 1]];
      int r = 0;
      std::array<int, 2> shared{};
      int n = 0;
      for (int q = 0; q < 3; ++q) {
        if (has_vertex(strip[j], pt[q]) && n < 2)
          shared[static_cast<size_t>(n++)] = q;
        else
          r = q;
      }
      const Eigen::Vector2d u2 = flat[j - 1].p[shared[0]], v2 = flat[j - 1].p[shared[1]];
      const Eigen::Vector2d r2 = flat[j - 1].p[r];
      Portal& p = portals[j];
      // Leaving the side r is on: the edge's end on the traveller's left is v when r
      // lies left of u->v.
      if (cross2(v2 - u2, r2 - u2) > 0) {
        p.left = pt[shared[1]], p.right = pt[shared[0]], p.left2 = v2, p.right2 = u2;
      } else {
        p.left = pt[shared[0]], p.right = pt[shared[1]], p.left2 = u2, p.right2 = v2;
      }
    }
    return portals;
  }

  // The taut path through the portals (the "simple stupid funnel").
  static std::vector<Apex> funnel(const std::vector<Portal>& portals) {
    std::vector<Apex> apexes{{0, true}};
    Eigen::Vector2d apex = portals[0].left2, left = apex, right = apex;
    size_t apex_i = 0, left_i = 0, right_i = 0;
    size_t i = 1;
    // A new corner at one leg's end: the funnel starts again from there.
    auto restart = [&](bool on_left) {
      apex_i = on_left ? left_i : right_i;
      apexes.push_back({apex_i, on_left});
      apex = on_left ? left : right;
      left = right = apex;
      left_i = right_i = apex_i;
      i = apex_i;
    };
    for (; i < portals.size(); ++i) {
      const Eigen::Vector2d& l = portals[i].left2;
      const Eigen::Vector2d& r = portals[i].right2;
      if (cross2(right - apex, r - apex) >= 0) {  // r tightens the right leg
        if (apex == right || cross2(left - apex, r - apex) < 0) {
          right = r;
          right_i = i;
        } else {  // crosses the left leg: the path turns round the left leg's end
          restart(true);
          continue;
        }
      }
      if (cross2(left - apex, l - apex) <= 0) {  // l tightens the left leg
        if (apex == left || cross2(right - apex, l - apex) > 0) {
          left = l;
          left_i = i;
        } else {
          restart(false);
          continue;
        }
      }
    }
    // The goal may already be in, pushed as a leg's end on the last portal.
    if (apexes.back().portal != portals.size() - 1) apexes.push_back({portals.size() - 1, true});
    return apexes;
  }

  static double taut_length(const std::vector<Portal>& portals, const std::vector<Apex>& apexes) {
    double s = 0;
    for (size_t k = 0; k + 1 < apexes.size(); ++k)
      s += (apex_point(portals, apexes[k + 1]) - apex_point(portals, apexes[k])).norm();
    return s;
  }
  static uint32_t apex_vertex(const std::vector<Portal>& portals, const Apex& a) {
    return a.left ? portals[a.portal].left : portals[a.portal].right;
  }
  static const Eigen::Vector2d& apex_point(const std::vector<Portal>& portals, const Apex& a) {
    return a.left ? portals[a.portal].left2 : portals[a.portal].right2;
  }

  // Re-routes the strip round the far side of every corner vertex where that side is
  // shorter. Returns whether anything changed.
  bool reroute(std::vector<uint32_t>& strip, const std::vector<Flat>& flat, const std::vector<Portal>& portals,
               const std::vector<Apex>& apexes, size_t* count) const {
    struct Change {
      size_t s, e;
      std::vector<uint32_t> fan;
    };
    std::vector<Change> changes;
    size_t last_end = 0;
    for (size_t k = 1; k + 1 < apexes.size(); ++k) {
      const uint32_t v = apex_vertex(portals, apexes[k]);
      // Portal i lies between strip triangles i-1 and i; both hold v.
      size_t s = apexes[k].portal - 1, e = apexes[k].portal;
      while (s > 0 && has_vertex(strip[s - 1], v)) --s;
      while (e + 1 < strip.size() && has_vertex(strip[e + 1], v)) ++e;
      if (e <= s || (!changes.empty() && s <= last_end)) continue;
      // The spokes at the run's two ends that the run does not cross.
      auto outer_spoke = [&](size_t j, size_t inner_j) {
        const Triangle& t = mesh_.triangles[strip[j]];
        for (int q = 0; q < 3; ++q)
          if (t[q] != v && !has_vertex(strip[inner_j], t[q])) return q;
        return -1;
      };
      const int os = outer_spoke(s, s + 1), oe = outer_spoke(e, e - 1);
      if (os < 0 || oe < 0) continue;
      const Triangle& ts = mesh_.triangles[strip[s]];
      // The other way round v, from T_s across its outer spoke to T_e.
      std::vector<uint32_t> fan;
      double other = 0;
      uint32_t cur = strip[s], spoke = ts[static_cast<size_t>(os)];
      bool closed = false;
      for (int guard = 0; guard < 64; ++guard) {
        const uint32_t next = across(cur, v, spoke);
        if (next == kNone) break;
        if (next == strip[e]) {
          closed = true;
          break;
        }
        fan.push_back(next);
        other += corner_angle(next, v);
        const Triangle& nt = mesh_.triangles[next];
        uint32_t nspoke = kNone;
        for (uint32_t q : nt)
          if (q != v && q != spoke) nspoke = q;
        cur = next;
        spoke = nspoke;
      }
      if (!closed) continue;
      // The path's angle on that side adds the parts of T_s and T_e beyond it.
      const Eigen::Vector2d v2 = apex_point(portals, apexes[k]);
      const Eigen::Vector2d in = apex_point(portals, apexes[k - 1]) - v2;
      const Eigen::Vector2d out = apex_point(portals, apexes[k + 1]) - v2;
      other += angle_between(flat[s].p[static_cast<size_t>(os)] - v2, in);
      other += angle_between(flat[e].p[static_cast<size_t>(oe)] - v2, out);
      if (other < M_PI - 1e-6) {
        changes.push_back({s, e, std::move(fan)});
        last_end = e;
      }
    }
    for (auto it = changes.rbegin(); it != changes.rend(); ++it) {
      std::vector<uint32_t> next(strip.begin(), strip.begin() + static_cast<std::ptrdiff_t>(it->s) + 1);
      next.insert(next.end(), it->fan.begin(), it->fan.end());
      next.insert(next.end(), strip.begin() + static_cast<std::ptrdiff_t>(it->e), strip.end());
      strip = std::move(next);
    }
    *count += changes.size();
    return !changes.empty();
  }

  // The path in the world: its corners, and where it crosses each portal between them.
  void trace(const std::vector<uint32_t>& strip, const std::vector<Portal>& portals, const std::vector<Apex>& apexes,
             SurfacePath* out) const {
    const bool has_conf = mesh_.confidence.size() == mesh_.vertices.size();
    auto conf = [&](uint32_t v) { return has_conf ? mesh_.confidence[v] : 1.f; };
    std::vector<float> along;  // the confidence at each point of out->path
    auto push = [&](const Eigen::Vector3d& p, float c) {
      if (out->path.empty() || (out->path.back() - p).norm() > 1e-9) {
        out->path.push_back(p);
        along.push_back(c);
      } else {
        along.back() = std::min(along.back(), c);
      }
      out->min_confidence = std::min(out->min_confidence, c);
    };
    // Confidence at the ends: their triangles' corners (the path starts inside them).
    auto tri_conf = [&](uint32_t t) {
      const Triangle& tr = mesh_.triangles[t];
      return std::min({conf(tr[0]), conf(tr[1]), conf(tr[2])});
    };
    out->path.clear();
    out->value_mm = 0;
    push(out->from, tri_conf(strip.front()));
    for (size_t k = 0; k + 1 < apexes.size(); ++k) {
      const Eigen::Vector2d a2 = apex_point(portals, apexes[k]), b2 = apex_point(portals, apexes[k + 1]);
      out->value_mm += (b2 - a2).norm();
      for (size_t i = apexes[k].portal + 1; i < apexes[k + 1].portal; ++i) {
        const Portal& p = portals[i];
        const Eigen::Vector2d d = b2 - a2, e = p.left2 - p.right2;
        const double den = cross2(d, e);
        double s = 0;
        if (std::abs(den) > 0) s = std::clamp(cross2(d, p.right2 - a2) / -den, 0.0, 1.0);
        push(vertex(p.right) + s * (vertex(p.left) - vertex(p.right)),
             static_cast<float>(conf(p.right) + s * (conf(p.left) - conf(p.right))));
      }
      if (k + 2 < apexes.size()) {
        const uint32_t v = apex_vertex(portals, apexes[k + 1]);
        push(vertex(v), conf(v));
      }
    }
    push(out->to, tri_conf(strip.back()));
    out->fill_bound_mm = filled_stretch_excess_mm(out->path, along, false).value_or(0);
  }

  const TriangleMesh& mesh_;
  std::vector<Eigen::Vector3d> centroids_;
  double cell_ = 1;
  std::vector<std::pair<uint64_t, uint32_t>> cells_;  // (cell key, vertex), sorted
  // The search's scratch arrays (one query at a time).
  mutable std::vector<double> dist_;
  mutable std::vector<uint32_t> prev_;
  mutable std::vector<uint8_t> state_;
  std::vector<uint32_t> offset_, incident_;  // vertex -> triangles
  std::vector<uint32_t> neighbour_;          // 3 per triangle: across edge (t[i], t[i+1])
};

SurfacePaths::SurfacePaths(const TriangleMesh& mesh) : impl_(std::make_unique<Impl>(mesh)) {}
SurfacePaths::~SurfacePaths() = default;

StatusOr<SurfacePath> SurfacePaths::shortest(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                                             const SurfacePathOptions& options) const {
  // A body has more than one locally shortest path between two points (over a
  // muscle's ridge or round it), and which one the strip settles into depends on
  // the Dijkstra strip it starts from. The search from each end starts from a
  // different strip: the shorter of the two. (Acromion to back neck point on a
  // true body: 253.6 mm one way, 240.2 the other.)
  ASSIGN_OR_RETURN(SurfacePath there, impl_->find(from, to, options));
  StatusOr<SurfacePath> back = impl_->find(to, from, options);
  if (!back.ok() || back->path_mm >= there.path_mm) return there;
  SurfacePath out = *std::move(back);
  std::reverse(out.path.begin(), out.path.end());
  std::swap(out.from, out.to);
  out.reroutes += there.reroutes;
  return out;
}

StatusOr<SurfacePath> mesh_surface_path(const TriangleMesh& mesh, const Eigen::Vector3d& from,
                                        const Eigen::Vector3d& to, const SurfacePathOptions& options) {
  if (mesh.triangles.empty()) return invalid_argument("the mesh has no triangles");
  return SurfacePaths(mesh).shortest(from, to, options);
}

}  // namespace bodyscan
