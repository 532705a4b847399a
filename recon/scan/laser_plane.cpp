#include "recon/scan/laser_plane.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace bodyscan {

const char* to_string(TriangulationMethod m) {
  return m == TriangulationMethod::kTwoPlaneRay ? "two-plane ray" : "laser-plane homography";
}

Eigen::Vector3d LaserPlane::triangulate(const CameraCalibration& cal, const Eigen::Vector2d& corrected,
                                        TriangulationMethod method) const {
  if (method == TriangulationMethod::kLaserHomography) {
    const Eigen::Vector2d ab = apply_homography(image_to_plane, corrected);
    return origin + ab.x() * axis_a + ab.y() * axis_b;
  }
  return intersect(cal.ray(corrected));
}

Eigen::Vector2d LaserPlane::to_image(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d q = p - origin;
  const Eigen::Vector3d h = image_to_plane.inverse() * Eigen::Vector3d(q.dot(axis_a), q.dot(axis_b), 1.0);
  return h.hnormalized();
}

LaserPlaneFinder::LaserPlaneFinder(const CameraCalibration& cal, const LaserPlaneOptions& options)
    : cal_(cal), options_(options) {
  const double half = cal.frame.pole_half_length();
  for (Pole p : kPoles) {
    Line& l = lines_[static_cast<size_t>(p)];
    const double z = cal.frame.face_z(p, cal.side);
    const PlaneProjection& proj = cal.projection(p);
    l.a = proj.to_image({-half, z});
    l.b = proj.to_image({half, z});
    const Eigen::Vector2d d = l.b - l.a;
    const Eigen::Vector2d across = Eigen::Vector2d(-d.y(), d.x()).normalized();
    l.samples = std::max(2, static_cast<int>(d.norm() / options.step_px) + 1);
    l.band = std::max(0, static_cast<int>(std::lround(options.band_px)));
    l.raw.reserve(static_cast<size_t>(l.samples) * (2 * l.band + 1));
    for (int i = 0; i < l.samples; ++i) {
      const Eigen::Vector2d q = l.a + d * (static_cast<double>(i) / (l.samples - 1));
      for (int o = -l.band; o <= l.band; ++o) l.raw.push_back(cal.lens.distort(q + o * across).cast<float>());
    }
  }
}

namespace {

// frame - base at a raw position, bilinear, 0 outside the image.
float difference_at(const ImageView& f, const ImageView& b, const Eigen::Vector2f& p) {
  const float x = p.x(), y = p.y();
  if (!(x >= 0 && y >= 0 && x <= f.width - 1.001f && y <= f.height - 1.001f)) return 0;
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const float fx = x - x0, fy = y - y0;
  auto d = [&](int xx, int yy) {
    const int v = static_cast<int>(f.row(yy)[xx]) - static_cast<int>(b.row(yy)[xx]);
    return static_cast<float>(std::max(v, 0));
  };
  return (1 - fy) * ((1 - fx) * d(x0, y0) + fx * d(x0 + 1, y0)) +
         fy * ((1 - fx) * d(x0, y0 + 1) + fx * d(x0 + 1, y0 + 1));
}

// The plane through three points, as (unit normal, offset).
std::pair<Eigen::Vector3d, double> plane_through(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                                 const Eigen::Vector3d& c) {
  const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
  return {n, n.dot(a)};
}

// Least-squares plane of points.
std::pair<Eigen::Vector3d, double> plane_fit(const std::vector<Eigen::Vector3d>& pts) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& p : pts) c += p;
  c /= static_cast<double>(pts.size());
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  for (const auto& p : pts) m += (p - c) * (p - c).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(m);
  const Eigen::Vector3d n = es.eigenvectors().col(0);
  return {n, n.dot(c)};
}

}  // namespace

StatusOr<LaserPlane> LaserPlaneFinder::find(const ImageView& frame, const ImageView& base) const {
  LaserPlane plane;
  std::vector<float> profile;
  const int radius = std::max(1, static_cast<int>(std::lround(options_.radius_px / options_.step_px)));
  for (Pole p : kPoles) {
    const Line& l = lines_[static_cast<size_t>(p)];
    const int width = 2 * l.band + 1;
    profile.assign(static_cast<size_t>(l.samples), 0.f);
    int best = 0;
    for (int i = 0; i < l.samples; ++i) {
      float s = 0;
      for (int o = 0; o < width; ++o) s += difference_at(frame, base, l.raw[static_cast<size_t>(i * width + o)]);
      profile[static_cast<size_t>(i)] = s / static_cast<float>(width);
      if (profile[static_cast<size_t>(i)] > profile[static_cast<size_t>(best)]) best = i;
    }
    PoleStripe& ps = plane.poles[static_cast<size_t>(p)];
    ps.peak = profile[static_cast<size_t>(best)];
    if (ps.peak < options_.threshold) continue;
    double sw = 0, st = 0;
    for (int i = std::max(0, best - radius); i <= std::min(l.samples - 1, best + radius); ++i) {
      sw += profile[static_cast<size_t>(i)];
      st += profile[static_cast<size_t>(i)] * static_cast<double>(i);
    }
    const double t = st / sw / (l.samples - 1);
    ps.found = true;
    ps.pixel = l.a + t * (l.b - l.a);
    ps.world = cal_.projection(p).to_plane(ps.pixel);
  }

  // Three poles fix the plane: the near ones and the far top, which the subject
  // cannot hide; the far bottom stands in for whichever of them is missing.
  auto at = [&](Pole p) -> PoleStripe& { return plane.poles[static_cast<size_t>(p)]; };
  std::vector<Pole> primary;
  for (Pole p : {Pole::kNearBottom, Pole::kNearTop, Pole::kFarTop})
    if (at(p).found) primary.push_back(p);
  if (primary.size() < 3 && at(Pole::kFarBottom).found) primary.push_back(Pole::kFarBottom);
  if (primary.size() < 3) {
    std::string missing;
    for (Pole p : kPoles)
      if (!at(p).found) missing += std::string(missing.empty() ? "" : ", ") + to_string(p);
    return failed_precondition("camera '" + cal_.camera_id + "': the laser stripe crosses only " +
                               std::to_string(primary.size()) + " of the frame's 4 poles (none seen on the " + missing +
                               " pole) - is a laser off, or aimed past the frame?");
  }
  auto [n, d] = plane_through(at(primary[0]).world, at(primary[1]).world, at(primary[2]).world);
  for (Pole p : primary) at(p).used = true;
  Pole fourth = Pole::kFarBottom;
  for (Pole p : kPoles)
    if (!at(p).used) fourth = p;
  PoleStripe& f = at(fourth);
  const double off = f.found ? std::abs(n.dot(f.world) - d) : -1;
  if (f.found && off <= options_.max_off_plane_mm) {
    plane.fourth_point_mm = off;
    std::vector<Eigen::Vector3d> pts;
    for (Pole p : kPoles) pts.push_back(at(p).world);
    std::tie(n, d) = plane_fit(pts);
    f.used = true;
  }
  RETURN_IF_ERROR(complete_plane(cal_, n, d, &plane));
  return plane;
}

Status complete_plane(const CameraCalibration& cal, const Eigen::Vector3d& normal, double offset, LaserPlane* plane) {
  Eigen::Vector3d n = normal;
  double d = offset;
  if (n.z() < 0) n = -n, d = -d;  // a fixed sense, so planes of one laser compare
  plane->normal = n;
  plane->offset = d;
  auto at = [&](Pole p) -> PoleStripe& { return plane->poles[static_cast<size_t>(p)]; };
  // Poles the plane was not measured on get the points where it cuts them
  // (eq. 3.8-3.9, through the pole's two lights) and their images (eq. 3.7).
  for (Pole p : kPoles) {
    PoleStripe& f = at(p);
    if (f.used) continue;
    const Eigen::Vector3d p1 = cal.frame.light(p, cal.side, 0), p2 = cal.frame.light(p, cal.side, 1);
    const double u = (n.dot(p1) - d) / n.dot(p1 - p2);
    f.world = p1 + u * (p2 - p1);
    f.pixel = cal.projection(p).to_image({f.world.x(), f.world.z()});
    f.estimated = true;
    f.used = true;
  }
  // Eq. 3.6 on the four points, in plane coordinates.
  plane->origin = Eigen::Vector3d::Zero();
  for (Pole p : kPoles) plane->origin += at(p).world / 4.0;
  plane->origin -= (n.dot(plane->origin) - d) * n;
  plane->axis_a = (at(Pole::kNearTop).world - at(Pole::kNearBottom).world);
  plane->axis_a = (plane->axis_a - plane->axis_a.dot(n) * n).normalized();
  plane->axis_b = n.cross(plane->axis_a);
  std::vector<Eigen::Vector2d> image, on_plane;
  for (Pole p : kPoles) {
    const Eigen::Vector3d q = at(p).world - plane->origin;
    image.push_back(at(p).pixel);
    on_plane.emplace_back(q.dot(plane->axis_a), q.dot(plane->axis_b));
  }
  auto h = fit_homography(image, on_plane);
  if (!h.ok()) {
    return failed_precondition("camera '" + cal.camera_id +
                               "': the laser's pole points do not fix the image-to-plane "
                               "transform: " +
                               h.status().message());
  }
  plane->image_to_plane = *h;
  return {};
}

}  // namespace bodyscan
