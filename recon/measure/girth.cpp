#include "recon/measure/girth.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "recon/measure/fill_bound.hpp"

namespace bodyscan {

namespace {

double cross(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

double distance_to_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

// Whether the closed polygon (in the plane spanned by u, v) winds round p.
bool encloses(const std::vector<Eigen::Vector3d>& loop, const Eigen::Vector3d& p, const Eigen::Vector3d& u,
              const Eigen::Vector3d& v) {
  bool inside = false;
  const double px = p.dot(u), py = p.dot(v);
  for (size_t i = 0, j = loop.size() - 1; i < loop.size(); j = i++) {
    const double xi = loop[i].dot(u), yi = loop[i].dot(v), xj = loop[j].dot(u), yj = loop[j].dot(v);
    if ((yi > py) != (yj > py) && px < (xj - xi) * (py - yi) / (yj - yi) + xi) inside = !inside;
  }
  return inside;
}

// Points in the plane through `origin` spanned by u, v: their coordinates there.
std::vector<Eigen::Vector2d> flatten(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& origin,
                                     const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
  std::vector<Eigen::Vector2d> out;
  out.reserve(points.size());
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d q = p - origin;
    out.emplace_back(q.dot(u), q.dot(v));
  }
  return out;
}

// The tape around points of one part: hull in the plane, back in 3-D.
void measure_around(const std::vector<Eigen::Vector3d>& points, const Plane& plane, Girth* g) {
  Eigen::Vector3d u, v;
  plane_basis(plane.normal, &u, &v);
  const std::vector<Eigen::Vector2d> hull = convex_hull(flatten(points, plane.point, u, v));
  g->value_mm = closed_length(hull);
  g->tape.clear();
  for (const Eigen::Vector2d& h : hull) g->tape.push_back(plane.point + h.x() * u + h.y() * v);
}

}  // namespace

bool loops_cross(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b) {
  Eigen::AlignedBox2d ba, bb;
  for (const Eigen::Vector2d& p : a) ba.extend(p);
  for (const Eigen::Vector2d& p : b) bb.extend(p);
  if (!ba.intersects(bb)) return false;
  const Eigen::AlignedBox2d common = ba.intersection(bb);
  // Only the edges that reach the boxes' common part can cross.
  auto edges_in = [&](const std::vector<Eigen::Vector2d>& l) {
    std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> e;
    for (size_t i = 0; i < l.size(); ++i) {
      const Eigen::Vector2d& p = l[i];
      const Eigen::Vector2d& q = l[(i + 1) % l.size()];
      if (Eigen::AlignedBox2d(p.cwiseMin(q), p.cwiseMax(q)).intersects(common)) e.emplace_back(p, q);
    }
    return e;
  };
  const auto ea = edges_in(a), eb = edges_in(b);
  for (const auto& [p, q] : ea)
    for (const auto& [r, t] : eb) {
      const double d1 = cross(p, q, r), d2 = cross(p, q, t), d3 = cross(r, t, p), d4 = cross(r, t, q);
      if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
    }
  return false;
}

void plane_basis(const Eigen::Vector3d& normal, Eigen::Vector3d* u, Eigen::Vector3d* v) {
  const Eigen::Vector3d n = normal.normalized();
  const Eigen::Vector3d helper = std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  *u = (helper - helper.dot(n) * n).normalized();
  *v = n.cross(*u);
}

std::vector<Eigen::Vector2d> convex_hull(std::vector<Eigen::Vector2d> p) {
  std::sort(p.begin(), p.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3) return p;
  std::vector<Eigen::Vector2d> h(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {  // lower hull
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (size_t i = p.size() - 1, t = k + 1; i-- > 0;) {  // upper hull
    while (k >= t && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  h.resize(k - 1);  // the last point is the first
  return h;
}

namespace {
template <typename V>
double closed_length_of(const std::vector<V>& polygon) {
  double sum = 0;
  for (size_t i = 0; i < polygon.size(); ++i) sum += (polygon[(i + 1) % polygon.size()] - polygon[i]).norm();
  return polygon.size() < 2 ? 0 : sum;
}
}  // namespace

void drop_nested_loops(std::vector<SectionLoop>* loops, const Plane& plane) {
  if (loops->size() < 2) return;
  Eigen::Vector3d u, v;
  plane_basis(plane.normal, &u, &v);
  std::vector<char> nested(loops->size(), 0);
  for (size_t i = 0; i < loops->size(); ++i) {
    const SectionLoop& a = (*loops)[i];
    if (!a.closed || a.points.empty()) continue;
    for (size_t j = 0; j < loops->size() && !nested[i]; ++j)
      nested[i] = j != i && (*loops)[j].closed && encloses((*loops)[j].points, a.points.front(), u, v);
  }
  size_t k = 0;
  for (size_t i = 0; i < loops->size(); ++i)
    if (!nested[i]) {
      if (k != i) (*loops)[k] = std::move((*loops)[i]);
      ++k;
    }
  loops->resize(k);
}

double closed_length(const std::vector<Eigen::Vector2d>& polygon) { return closed_length_of(polygon); }
double closed_length(const std::vector<Eigen::Vector3d>& polygon) { return closed_length_of(polygon); }

StatusOr<Girth> mesh_girth(const TriangleMesh& mesh, const Plane& plane, const std::optional<Eigen::Vector3d>& near) {
  return mesh_girth(mesh, plane, near, nullptr);
}

StatusOr<Girth> mesh_girth(const TriangleMesh& mesh, const Plane& plane_in, const std::optional<Eigen::Vector3d>& near,
                           const std::vector<uint32_t>* triangles) {
  Plane plane = plane_in;
  if (!(plane.normal.norm() > 0)) return invalid_argument("girth: the plane's normal is zero");
  plane.normal.normalize();
  std::vector<SectionLoop> loops = plane_section(mesh, plane, triangles);
  const size_t cut = loops.size();
  loops.erase(std::remove_if(loops.begin(), loops.end(), [](const SectionLoop& l) { return !l.closed; }), loops.end());
  if (cut == 0) return not_found("girth: the plane does not cut the body");
  if (loops.empty())
    return not_found("girth: the plane cuts only the body's open border, no closed loop to measure around");
  std::vector<SectionLoop> closed;  // nested ones too: one may cross the loop meant
  if (loops.size() > 1) closed = loops;
  drop_nested_loops(&loops, plane);
  size_t best = 0;
  if (near) {
    double best_d = std::numeric_limits<double>::infinity();
    // A loop round the point (a limb's axis, the neck's centre) wins outright;
    // otherwise the loop passing nearest (a point picked on the skin).
    Eigen::Vector3d u, v;
    plane_basis(plane.normal, &u, &v);
    for (size_t i = 0; i < loops.size(); ++i) {
      const std::vector<Eigen::Vector3d>& l = loops[i].points;
      if (encloses(l, *near, u, v)) {
        best = i;
        break;
      }
      for (size_t k = 0; k < l.size(); ++k) {
        const double d = distance_to_segment(*near, l[k], l[(k + 1) % l.size()]);
        if (d < best_d) best_d = d, best = i;
      }
    }
  } else {
    double longest = -1;
    for (size_t i = 0; i < loops.size(); ++i) {
      Girth g;
      measure_around(loops[i].points, plane, &g);
      if (g.value_mm > longest) longest = g.value_mm, best = i;
    }
  }
  Girth g;
  g.plane = plane;
  g.loops_cut = cut;
  g.loop = loops[best].points;
  g.loop_length_mm = closed_length(g.loop);
  g.min_confidence = *std::min_element(loops[best].confidence.begin(), loops[best].confidence.end());
  g.fill_bound_mm = filled_stretch_excess_mm(g.loop, loops[best].confidence, true);
  // Loops that cross the one meant are the same part: a reconstructed surface that
  // passes through itself (a hole's fill through the skin) cuts one ankle as two
  // overlapping loops, and the tape goes round both (drop_nested_loops may have
  // dropped the other as lying inside it).
  std::vector<Eigen::Vector3d> crossing;
  if (!closed.empty()) {
    Eigen::Vector3d u, v;
    plane_basis(plane.normal, &u, &v);
    std::vector<std::vector<Eigen::Vector2d>> flat(closed.size());
    for (size_t i = 0; i < closed.size(); ++i) flat[i] = flatten(closed[i].points, plane.point, u, v);
    std::vector<bool> meant(closed.size()), taken(closed.size());
    for (size_t i = 0; i < closed.size(); ++i) meant[i] = taken[i] = closed[i].points == g.loop;
    for (bool grew = true; grew;) {
      grew = false;
      for (size_t i = 0; i < closed.size(); ++i)
        for (size_t j = 0; j < closed.size() && !taken[i]; ++j)
          if (taken[j] && loops_cross(flat[j], flat[i])) taken[i] = grew = true;
    }
    for (size_t i = 0; i < closed.size(); ++i) {
      if (!taken[i] || meant[i]) continue;
      crossing.insert(crossing.end(), closed[i].points.begin(), closed[i].points.end());
      if (*std::min_element(closed[i].confidence.begin(), closed[i].confidence.end()) < kMeasuredConfidence)
        g.fill_bound_mm.reset();
      g.min_confidence =
          std::min(g.min_confidence, *std::min_element(closed[i].confidence.begin(), closed[i].confidence.end()));
    }
  }
  if (crossing.empty()) {
    measure_around(g.loop, plane, &g);
  } else {
    crossing.insert(crossing.end(), g.loop.begin(), g.loop.end());
    measure_around(crossing, plane, &g);
  }
  return g;
}

StatusOr<Girth> cloud_girth(const PointCloud& cloud, const Plane& plane_in, const std::optional<Eigen::Vector3d>& near,
                            double slab_mm, double gap_mm) {
  Plane plane = plane_in;
  if (!(plane.normal.norm() > 0)) return invalid_argument("girth: the plane's normal is zero");
  plane.normal.normalize();
  std::vector<Eigen::Vector3d> slab;
  for (const Vec3f& p : cloud.positions) {
    const Eigen::Vector3d q = p.cast<double>();
    const double d = plane.signed_distance(q);
    if (std::abs(d) <= slab_mm) slab.push_back(q - d * plane.normal);
  }
  if (slab.size() < 3)
    return not_found("girth: fewer than 3 points lie within " + std::to_string(slab_mm) + " mm of the plane");
  // Parts: single-linkage groups at gap_mm (union-find over a sort by one axis).
  std::vector<size_t> parent(slab.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  std::vector<size_t> order(slab.size());
  std::iota(order.begin(), order.end(), 0);
  Eigen::Vector3d u, v;
  plane_basis(plane.normal, &u, &v);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return slab[a].dot(u) < slab[b].dot(u); });
  for (size_t i = 0; i < order.size(); ++i)
    for (size_t j = i + 1; j < order.size() && slab[order[j]].dot(u) - slab[order[i]].dot(u) <= gap_mm; ++j)
      if ((slab[order[i]] - slab[order[j]]).norm() <= gap_mm) parent[find(order[i])] = find(order[j]);
  std::vector<std::vector<Eigen::Vector3d>> parts;
  std::vector<long> part_of(slab.size(), -1);
  for (size_t i = 0; i < slab.size(); ++i) {
    const size_t r = find(i);
    if (part_of[r] < 0) part_of[r] = static_cast<long>(parts.size()), parts.emplace_back();
    parts[static_cast<size_t>(part_of[r])].push_back(slab[i]);
  }
  size_t best = 0;
  double best_score = -std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < parts.size(); ++i) {
    if (parts[i].size() < 3) continue;
    double score;
    if (near) {
      double d = std::numeric_limits<double>::infinity();
      for (const Eigen::Vector3d& p : parts[i]) d = std::min(d, (p - *near).norm());
      score = -d;
    } else {
      Girth g;
      measure_around(parts[i], plane, &g);
      score = g.value_mm;
    }
    if (score > best_score) best_score = score, best = i;
  }
  if (parts[best].size() < 3) return not_found("girth: no part of the cloud has 3 points in the plane");
  Girth g;
  g.plane = plane;
  g.loops_cut = parts.size();
  g.loop = parts[best];
  measure_around(g.loop, plane, &g);
  g.loop_length_mm = 0;  // unordered points: no path along the skin
  return g;
}

namespace {

// Where q meets a closed polygon: the distance along it from its first corner to the
// point nearest q, and that point.
std::pair<double, Eigen::Vector3d> place_on(const std::vector<Eigen::Vector3d>& polygon, const Eigen::Vector3d& q) {
  double best = std::numeric_limits<double>::infinity(), along = 0, at = 0;
  Eigen::Vector3d nearest = polygon.front();
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector3d& a = polygon[i];
    const Eigen::Vector3d ab = polygon[(i + 1) % polygon.size()] - a;
    const double len2 = ab.squaredNorm();
    const double t = len2 > 0 ? std::clamp((q - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    const Eigen::Vector3d p = a + t * ab;
    if ((p - q).norm() < best) best = (p - q).norm(), at = along + t * std::sqrt(len2), nearest = p;
    along += std::sqrt(len2);
  }
  return {at, nearest};
}

}  // namespace

StatusOr<Arc> mesh_arc(const TriangleMesh& mesh, const Plane& plane, const Eigen::Vector3d& from,
                       const Eigen::Vector3d& to) {
  ASSIGN_OR_RETURN(Girth g, mesh_girth(mesh, plane, Eigen::Vector3d(0.5 * (from + to))));
  if (g.tape.size() < 3) return not_found("arc: the section is too small to measure along");
  const auto [sa, pa] = place_on(g.tape, from);
  const auto [sb, pb] = place_on(g.tape, to);
  const double forward = sb >= sa ? sb - sa : g.value_mm - (sa - sb);  // along the tape's order
  Arc arc;
  arc.value_mm = std::min(forward, g.value_mm - forward);
  arc.other_way_mm = g.value_mm - arc.value_mm;
  // The path: the corners passed on the shorter way, between the two places.
  const bool ahead = forward <= g.value_mm - forward;
  const double start = ahead ? sa : sb, length = arc.value_mm;
  arc.path.push_back(ahead ? pa : pb);
  double along = 0;
  std::vector<std::pair<double, Eigen::Vector3d>> corners;  // (distance past start, corner)
  for (size_t i = 0; i < g.tape.size(); ++i) {
    double d = along - start;
    if (d < 0) d += g.value_mm;
    if (d > 0 && d < length) corners.emplace_back(d, g.tape[i]);
    along += (g.tape[(i + 1) % g.tape.size()] - g.tape[i]).norm();
  }
  std::sort(corners.begin(), corners.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  for (const auto& c : corners) arc.path.push_back(c.second);
  arc.path.push_back(ahead ? pb : pa);
  if (!ahead) std::reverse(arc.path.begin(), arc.path.end());  // from `from` to `to`
  arc.girth = std::move(g);
  return arc;
}

}  // namespace bodyscan
