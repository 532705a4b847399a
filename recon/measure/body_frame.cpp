#include "recon/measure/body_frame.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <tbb/parallel_for.h>

#include "recon/measure/body_slicer.hpp"

namespace bodyscan {

namespace {

// The trunk's cuts: from the hips' top to under the arms, as fractions of the
// height. Below, the hands of a hanging arm can reach the hips; above, the
// armpits join the arms to the chest.
constexpr double kTrunkFrom = 0.50, kTrunkTo = 0.70, kTrunkStep = 0.01;
// Each cut is resampled to this many points, equally spaced along it.
constexpr int kLoopPoints = 256;
// The points whose mirror images lie farthest from the cut (an arm resting on the
// trunk, a hole's patch) are left out of the symmetry: this share is kept.
constexpr double kSymmetryKept = 0.9;
// The feet are cut this high (fractions of the height), the legs above the ankles.
constexpr double kFeetAt[] = {0.01, 0.02};
constexpr double kLegsAt = 0.07;

using Vec2 = Eigen::Vector2d;

struct Cut {
  std::vector<Vec2> points;  // (x, z), closed, equally spaced
  Vec2 centroid;             // of the enclosed area
};

std::vector<Vec2> resampled(const std::vector<Eigen::Vector3d>& loop, int n) {
  std::vector<double> s(loop.size() + 1, 0.0);
  for (size_t i = 0; i < loop.size(); ++i) {
    const Eigen::Vector3d& a = loop[i];
    const Eigen::Vector3d& b = loop[(i + 1) % loop.size()];
    s[i + 1] = s[i] + std::hypot(b.x() - a.x(), b.z() - a.z());
  }
  std::vector<Vec2> out;
  out.reserve(n);
  size_t k = 0;
  for (int j = 0; j < n; ++j) {
    const double t = s.back() * j / n;
    while (k + 1 < loop.size() && s[k + 1] < t) ++k;
    const Eigen::Vector3d& a = loop[k];
    const Eigen::Vector3d& b = loop[(k + 1) % loop.size()];
    const double f = s[k + 1] > s[k] ? (t - s[k]) / (s[k + 1] - s[k]) : 0.0;
    out.emplace_back(a.x() + f * (b.x() - a.x()), a.z() + f * (b.z() - a.z()));
  }
  return out;
}

// Squared distance from p to the closed polyline `poly`: to the nearest vertex's
// two segments. The vertex search runs over plain doubles: it is the frame
// search's inner loop, and the sanitizers' build does not inline Eigen's small
// expressions.
double squared_distance(const Vec2& p, const std::vector<Vec2>& poly) {
  static_assert(sizeof(Vec2) == 2 * sizeof(double), "a polyline is x, z pairs back to back");
  const double* xz = poly.data()->data();
  const double px = p.x(), pz = p.y();
  const size_t n = poly.size();
  size_t best = 0;
  double best_d = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < n; ++i) {
    const double dx = xz[2 * i] - px, dz = xz[2 * i + 1] - pz;
    if (const double d = dx * dx + dz * dz; d < best_d) best_d = d, best = i;
  }
  for (const size_t j : {(best + n - 1) % n, best}) {
    const Vec2 &a = poly[j], &b = poly[(j + 1) % n];
    const Vec2 ab = b - a;
    const double len2 = ab.squaredNorm();
    if (len2 <= 0) continue;
    const double t = std::clamp((p - a).dot(ab) / len2, 0.0, 1.0);
    best_d = std::min(best_d, (a + t * ab - p).squaredNorm());
  }
  return best_d;
}

// RMS distance of the cuts' points mirrored in the line through each cut's
// centroid with normal (cos a, sin a), over the best kSymmetryKept of them.
double asymmetry(const std::vector<Cut>& cuts, double a) {
  const Vec2 u(std::cos(a), std::sin(a));
  std::vector<std::vector<double>> per_cut(cuts.size());
  tbb::parallel_for(size_t{0}, cuts.size(), [&](size_t c) {
    const Cut& cut = cuts[c];
    for (size_t i = 0; i < cut.points.size(); i += 2) {
      const Vec2& p = cut.points[i];
      const Vec2 mirrored = p - 2 * (p - cut.centroid).dot(u) * u;
      per_cut[c].push_back(squared_distance(mirrored, cut.points));
    }
  });
  std::vector<double> d;
  for (const auto& x : per_cut) d.insert(d.end(), x.begin(), x.end());
  const size_t kept = std::max<size_t>(1, static_cast<size_t>(kSymmetryKept * d.size()));
  std::nth_element(d.begin(), d.begin() + (kept - 1), d.end());
  double sum = 0;
  for (size_t i = 0; i < kept; ++i) sum += d[i];
  return std::sqrt(sum / kept);
}

}  // namespace

TriangleMesh transformed(const TriangleMesh& mesh, const Eigen::Isometry3d& transform) {
  TriangleMesh out = mesh;
  const Eigen::Matrix3f r = transform.linear().cast<float>();
  const Eigen::Vector3f t = transform.translation().cast<float>();
  for (Vec3f& v : out.vertices) v = r * v + t;
  for (Vec3f& n : out.normals) n = r * n;
  return out;
}

StatusOr<BodyFrame> find_body_frame(const TriangleMesh& mesh, const BodyFrameOptions& options) {
  if (mesh.triangles.empty()) return invalid_argument("measure: the mesh has no triangles");
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Vec3f& v : mesh.vertices)
    lo = std::min(lo, static_cast<double>(v.y())), hi = std::max(hi, static_cast<double>(v.y()));
  BodyFrame frame;
  frame.floor_y = options.floor_y.value_or(lo);
  frame.height = hi - frame.floor_y;
  const double h = frame.height;
  if (!(h > 500)) return invalid_argument("measure: the body is under 500 mm tall; is it a standing body in mm, Y up?");
  const BodySlicer slicer(mesh, lo, hi, 2.0);

  // The trunk: the cut's longest loop at each level.
  std::vector<Cut> cuts;
  for (double f = kTrunkFrom; f <= kTrunkTo + 1e-9; f += kTrunkStep) {
    const std::vector<Ring> rings = slicer.rings(frame.floor_y + f * h);
    const Ring* trunk = nullptr;
    for (const Ring& r : rings)
      if (r.points.size() >= 8 && (!trunk || r.girth > trunk->girth)) trunk = &r;
    if (trunk) cuts.push_back({resampled(trunk->points, kLoopPoints), {trunk->centroid.x(), trunk->centroid.z()}});
  }
  if (cuts.size() < 10)
    return not_found("measure: no trunk between half and 70 % of the height; is the body standing?");

  // The sagittal plane: the mirror that fits the trunk's cuts best, searched over
  // every direction, then refined.
  double best_a = 0, best_cost = std::numeric_limits<double>::infinity();
  constexpr double kCoarse = M_PI / 36;  // 5 degrees: the cost falls smoothly to its minimum over more than that
  for (double a = 0; a < M_PI; a += kCoarse)
    if (const double c = asymmetry(cuts, a); c < best_cost) best_cost = c, best_a = a;
  {
    double x0 = best_a - kCoarse, x1 = best_a + kCoarse;
    const double r = (std::sqrt(5.0) - 1) / 2;
    double c = x1 - r * (x1 - x0), d = x0 + r * (x1 - x0);
    double fc = asymmetry(cuts, c), fd = asymmetry(cuts, d);
    while (x1 - x0 > 1e-5) {
      if (fc < fd) {
        x1 = d, d = c, fd = fc, c = x1 - r * (x1 - x0), fc = asymmetry(cuts, c);
      } else {
        x0 = c, c = d, fc = fd, d = x0 + r * (x1 - x0), fd = asymmetry(cuts, d);
      }
    }
    const double a = 0.5 * (x0 + x1), fa = asymmetry(cuts, a);
    if (fa < best_cost) best_cost = fa, best_a = a;
  }
  frame.asymmetry_rms_mm = best_cost;
  // Left (either way for now) and forward = left x up.
  Eigen::Vector3d left(std::cos(best_a), 0, std::sin(best_a));
  Eigen::Vector3d forward = left.cross(Eigen::Vector3d::UnitY());

  // Front or back: each foot's footprint reaches forward of its leg above the ankle.
  std::vector<Eigen::Vector3d> legs;
  for (const Ring& r : slicer.rings(frame.floor_y + kLegsAt * h)) legs.push_back(r.centroid);
  double reach = 0;
  int feet = 0;
  for (const double at : kFeetAt)
    for (const Ring& foot : slicer.rings(frame.floor_y + at * h)) {
      const Eigen::Vector3d* leg = nullptr;
      for (const Eigen::Vector3d& c : legs)
        if (!leg || (c - foot.centroid).squaredNorm() < (*leg - foot.centroid).squaredNorm()) leg = &c;
      if (!leg) continue;
      reach += (foot.centroid - *leg).dot(forward);
      ++feet;
    }
  frame.feet_forward_mm = feet > 0 ? reach / feet : 0.0;
  frame.front_from_feet = std::abs(frame.feet_forward_mm) >= kFeetEvidenceMm;
  if (frame.front_from_feet ? frame.feet_forward_mm < 0 : forward.z() < 0) {
    left = -left, forward = -forward, frame.feet_forward_mm = -frame.feet_forward_mm;
  }

  Vec2 centre = Vec2::Zero();
  for (const Cut& c : cuts) centre += c.centroid;
  centre /= static_cast<double>(cuts.size());
  frame.world_from_body.linear().col(0) = left;
  frame.world_from_body.linear().col(1) = Eigen::Vector3d::UnitY();
  frame.world_from_body.linear().col(2) = forward;
  frame.world_from_body.translation() = Eigen::Vector3d(centre.x(), frame.floor_y, centre.y());
  frame.turn_deg = std::atan2(forward.x(), forward.z()) * 180 / M_PI;
  return frame;
}

}  // namespace bodyscan
