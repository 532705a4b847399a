#include "recon/scan/triangulate.hpp"

#include <algorithm>
#include <cmath>

namespace bodyscan {

ScanVolume scan_volume(const ReferenceFrame& f) {
  ScanVolume v;
  // Two tubes in from the poles' centre lines: a stripe on a pole's face, a few
  // millimetres off by the plane's error at the frame's edge, stays out.
  const double x = 0.5 * f.width - 2 * f.tube, z = 0.5 * f.depth - 2 * f.tube;
  // The floor is the bottom frame's underside; points within 3 mm of it are floor.
  v.lo = {-x, -0.5 * f.tube + 3, -z};
  v.hi = {x, f.top_height - 0.5 * f.tube, z};
  return v;
}

std::vector<ColumnRange> stripe_windows(const CameraCalibration& cal, const LaserPlane& plane, const ScanVolume& volume,
                                        int pad) {
  // The plane's polygon inside the box: where it cuts the box's twelve edges.
  std::vector<Eigen::Vector3d> corners;
  for (int i = 0; i < 8; ++i)
    corners.emplace_back(i & 1 ? volume.hi.x() : volume.lo.x(), i & 2 ? volume.hi.y() : volume.lo.y(),
                         i & 4 ? volume.hi.z() : volume.lo.z());
  std::vector<Eigen::Vector3d> poly;
  for (int a = 0; a < 8; ++a)
    for (int bit : {1, 2, 4}) {
      if (a & bit) continue;
      const int b = a | bit;
      const double da = plane.normal.dot(corners[static_cast<size_t>(a)]) - plane.offset;
      const double db = plane.normal.dot(corners[static_cast<size_t>(b)]) - plane.offset;
      if ((da < 0) == (db < 0) || da == db) continue;
      const double t = da / (da - db);
      poly.push_back(corners[static_cast<size_t>(a)] +
                     t * (corners[static_cast<size_t>(b)] - corners[static_cast<size_t>(a)]));
    }
  std::vector<ColumnRange> rows(static_cast<size_t>(cal.height), ColumnRange{0, 0});
  if (poly.size() < 3) return rows;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& p : poly) c += p / static_cast<double>(poly.size());
  std::sort(poly.begin(), poly.end(), [&](const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
    return std::atan2((p - c).dot(plane.axis_b), (p - c).dot(plane.axis_a)) <
           std::atan2((q - c).dot(plane.axis_b), (q - c).dot(plane.axis_a));
  });
  // Its outline in the raw image, edges sampled every 10 mm (lens distortion bends them).
  std::vector<Eigen::Vector2d> outline;
  for (size_t i = 0; i < poly.size(); ++i) {
    const Eigen::Vector3d& p = poly[i];
    const Eigen::Vector3d& q = poly[(i + 1) % poly.size()];
    const int n = std::max(1, static_cast<int>((q - p).norm() / 10));
    for (int k = 0; k < n; ++k) outline.push_back(cal.lens.distort(plane.to_image(p + (q - p) * (double(k) / n))));
  }
  std::vector<double> lo(static_cast<size_t>(cal.height), 1e30), hi(static_cast<size_t>(cal.height), -1e30);
  auto mark = [&](int y, double x) {
    if (y < 0 || y >= cal.height) return;
    lo[static_cast<size_t>(y)] = std::min(lo[static_cast<size_t>(y)], x);
    hi[static_cast<size_t>(y)] = std::max(hi[static_cast<size_t>(y)], x);
  };
  for (size_t i = 0; i < outline.size(); ++i) {
    const Eigen::Vector2d& p = outline[i];
    const Eigen::Vector2d& q = outline[(i + 1) % outline.size()];
    const int y0 = static_cast<int>(std::floor(std::min(p.y(), q.y()))) - pad;
    const int y1 = static_cast<int>(std::ceil(std::max(p.y(), q.y()))) + pad;
    for (int y = y0; y <= y1; ++y) {
      const double t = q.y() == p.y() ? 0.5 : std::clamp((y - p.y()) / (q.y() - p.y()), 0.0, 1.0);
      mark(y, p.x() + t * (q.x() - p.x()));
    }
  }
  for (int y = 0; y < cal.height; ++y) {
    if (hi[static_cast<size_t>(y)] < lo[static_cast<size_t>(y)]) continue;
    rows[static_cast<size_t>(y)] = {
        std::max(0, static_cast<int>(std::floor(lo[static_cast<size_t>(y)])) - pad),
        std::min(cal.width, static_cast<int>(std::ceil(hi[static_cast<size_t>(y)])) + pad + 1)};
  }
  return rows;
}

float stripe_confidence(const StripeSample& s, int threshold) {
  return std::clamp((static_cast<float>(s.peak) - threshold) / (3.0f * threshold), 0.0f, 1.0f);
}

StatusOr<std::vector<StripeSample>> extract_plane_stripe(const CameraCalibration& cal, const LaserPlane* plane,
                                                         const ImageView& frame, const ImageView& base, int full_scale,
                                                         const TriangulateOptions& options) {
  std::vector<ColumnRange> windows;
  if (plane) windows = stripe_windows(cal, *plane, scan_volume(cal.frame), options.window_pad_px);
  return extract_stripe(frame, base, options.stripe, full_scale, plane ? &windows : nullptr);
}

float angle_confidence(double angle_deg, double full_angle_deg) {
  return static_cast<float>(
      std::clamp(std::sin(angle_deg * M_PI / 180) / std::sin(full_angle_deg * M_PI / 180), 0.0, 1.0));
}

size_t triangulate_samples(const CameraCalibration& cal, const LaserPlane& plane,
                           const std::vector<StripeSample>& samples, int full_scale, const PointSource& source,
                           const TriangulateOptions& options, const std::vector<SweepPlane>& others,
                           PointCloud* cloud) {
  const ScanVolume volume = scan_volume(cal.frame);
  const double floor_y = -0.5 * cal.frame.tube;
  size_t added = 0;
  for (const StripeSample& s : samples) {
    const Eigen::Vector2d corrected = cal.lens.correct({s.column, static_cast<double>(s.row)});
    const Ray3 r = cal.ray(corrected);
    const Eigen::Vector3d p = options.method == TriangulationMethod::kTwoPlaneRay
                                  ? plane.intersect(r)
                                  : plane.triangulate(cal, corrected, options.method);
    if (!p.allFinite() || !volume.contains(p)) continue;
    const double angle = std::asin(std::min(1.0, std::abs(r.direction.dot(plane.normal)))) * 180 / M_PI;
    if (angle < options.min_angle_deg) continue;
    if (!others.empty()) {
      if (r.direction.y() < 0) {
        const Eigen::Vector3d q = r.origin + (floor_y - r.origin.y()) / r.direction.y() * r.direction;
        bool ghost = false;
        for (const SweepPlane& o : others)
          ghost = ghost || std::abs(o.normal.dot(q) - o.offset) < options.floor_line_mm;
        if (ghost) continue;
      }
    }
    cloud->positions.push_back(p.cast<float>());
    cloud->intensity.push_back(static_cast<float>(s.peak) / static_cast<float>(full_scale));
    cloud->confidence.push_back(std::max(0.05f, stripe_confidence(s, options.stripe.threshold)) *
                                std::max(0.05f, angle_confidence(angle, options.full_angle_deg)));
    cloud->camera.push_back(source.camera);
    cloud->laser.push_back(source.laser);
    cloud->frame.push_back(source.frame);
    ++added;
  }
  return added;
}

}  // namespace bodyscan
