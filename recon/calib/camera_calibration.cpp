#include "recon/calib/camera_calibration.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace bodyscan {

namespace {

// Indices into a frame's four markers (sorted left to right): the near pair is the
// two farthest from the horizon.
std::array<int, 2> near_pair(const std::array<Eigen::Vector2d, 4>& m, bool top) {
  std::array<int, 4> idx = {0, 1, 2, 3};
  std::sort(idx.begin(), idx.end(), [&](int a, int b) {
    return top ? m[static_cast<size_t>(a)].y() < m[static_cast<size_t>(b)].y()
               : m[static_cast<size_t>(a)].y() > m[static_cast<size_t>(b)].y();
  });
  return {std::min(idx[0], idx[1]), std::max(idx[0], idx[1])};
}

bool is_lit(const Eigen::Vector2d& p, const std::vector<Marker>& lit) {
  for (const Marker& m : lit)
    if ((m.centre - p).norm() < 4.0) return true;
  return false;
}

}  // namespace

Ray3 CameraCalibration::ray(const Eigen::Vector2d& corrected) const {
  // Each plane's point in homogeneous form, w (X - C, Y - C, Z - C): a direction from
  // the centre that stays exact as the point recedes to infinity (w -> 0).
  Eigen::Vector3d dir = Eigen::Vector3d::Zero();
  for (const PlaneProjection* p : {&top, &bottom}) {
    const Eigen::Vector3d h = p->homography() * corrected.homogeneous();  // (X w, Z w, w)
    Eigen::Vector3d d(h.x() - centre.x() * h.z(), (p->plane_y() - centre.y()) * h.z(), h.y() - centre.z() * h.z());
    if (d.dot(forward) < 0) d = -d;
    dir += d.normalized();
  }
  return {centre, dir.normalized()};
}

std::array<std::array<Eigen::Vector2d, 2>, 4> name_markers(const FrameMarkers& markers, FrameSide side) {
  std::array<std::array<Eigen::Vector2d, 2>, 4> out{};
  for (bool top : {false, true}) {
    const std::array<Eigen::Vector2d, 4>& m = top ? markers.top : markers.bottom;
    const std::array<int, 2> near = near_pair(m, top);
    std::array<int, 2> far{};
    int k = 0;
    for (int i = 0; i < 4; ++i)
      if (i != near[0] && i != near[1]) far[static_cast<size_t>(k++)] = i;
    // The pairs are in image x order; world X runs the other way for a back camera.
    const bool flip = side == FrameSide::kBack;
    auto put = [&](Pole p, const std::array<int, 2>& pair) {
      out[static_cast<size_t>(p)] = {m[static_cast<size_t>(pair[flip ? 1 : 0])],
                                     m[static_cast<size_t>(pair[flip ? 0 : 1])]};
    };
    put(top ? Pole::kNearTop : Pole::kNearBottom, near);
    put(top ? Pole::kFarTop : Pole::kFarBottom, far);
  }
  return out;
}

StatusOr<FrameSide> identify_side(const FrameMarkers& all_lights, const std::vector<Marker>& front_lights) {
  int near_lit = 0, far_lit = 0;
  for (bool top : {false, true}) {
    const std::array<Eigen::Vector2d, 4>& m = top ? all_lights.top : all_lights.bottom;
    const std::array<int, 2> near = near_pair(m, top);
    for (int i = 0; i < 4; ++i) {
      if (!is_lit(m[static_cast<size_t>(i)], front_lights)) continue;
      (i == near[0] || i == near[1] ? near_lit : far_lit) += 1;
    }
  }
  if (near_lit == 4 && far_lit == 0) return FrameSide::kFront;
  if (far_lit == 4 && near_lit == 0) return FrameSide::kBack;
  return failed_precondition("with only the front poles' lights on, " + std::to_string(near_lit + far_lit) +
                             " of the camera's 8 markers lit (" + std::to_string(near_lit) + " near, " +
                             std::to_string(far_lit) +
                             " far) where its 4 near ones (a front camera) or its 4 far ones (a back camera) "
                             "should: check the frame-light circuits' wiring");
}

StatusOr<CameraCalibration> calibrate_camera(const std::string& camera_id, const LensCorrection& lens,
                                             const CameraCalibrationImages& images, const ReferenceFrame& frame,
                                             const MarkerOptions& options) {
  auto fail = [&](const std::string& step, const Status& s) {
    return Status(s.code(), "camera '" + camera_id + "': " + step + ": " + s.message());
  };
  auto all = find_markers(images.lights_on, images.lights_off, options);
  if (!all.ok()) return fail("frame markers", all.status());
  auto ordered = order_frame_markers(*all);
  if (!ordered.ok()) return fail("frame markers", ordered.status());
  auto front = find_markers(images.front_lights, images.lights_off, options);
  if (!front.ok()) return fail("front-pole lights", front.status());
  auto side = identify_side(*ordered, *front);
  if (!side.ok()) return fail("which side of the frame", side.status());

  std::array<std::array<Eigen::Vector2d, 2>, 4> markers = name_markers(*ordered, *side);
  for (auto& pole : markers)
    for (Eigen::Vector2d& p : pole) p = lens.correct(p);
  return camera_from_markers(camera_id, images.lights_on.width, images.lights_on.height, frame, lens, *side, markers);
}

StatusOr<CameraCalibration> camera_from_markers(const std::string& camera_id, int width, int height,
                                                const ReferenceFrame& frame, const LensCorrection& lens, FrameSide side,
                                                const std::array<std::array<Eigen::Vector2d, 2>, 4>& markers) {
  auto fail = [&](const std::string& step, const Status& s) {
    return Status(s.code(), "camera '" + camera_id + "': " + step + ": " + s.message());
  };
  CameraCalibration cal;
  cal.camera_id = camera_id;
  cal.width = width;
  cal.height = height;
  cal.frame = frame;
  cal.lens = lens;
  cal.side = side;
  cal.markers = markers;
  for (bool top : {false, true}) {
    std::vector<Eigen::Vector2d> image, plane;
    for (Pole p : kPoles) {
      if (is_top(p) != top) continue;
      for (int i = 0; i < 2; ++i) {
        image.push_back(cal.markers[static_cast<size_t>(p)][static_cast<size_t>(i)]);
        const Eigen::Vector3d w = frame.light(p, side, i);
        plane.emplace_back(w.x(), w.z());
      }
    }
    auto fit = PlaneProjection::fit(image, plane, top ? frame.top_height : 0.0);
    if (!fit.ok()) return fail(top ? "top-plane transform" : "bottom-plane transform", fit.status());
    (top ? cal.top : cal.bottom) = *fit;
  }

  // The centre: where the two-plane rays of the image's top and bottom bands meet.
  // Those look well up or down, so both of their plane points are near; rows by the
  // horizon meet both planes far away and would only add noise.
  std::vector<Ray3> rays;
  for (double v : {0.02, 0.08, 0.14, 0.86, 0.92, 0.98})
    for (int i = 0; i <= 8; ++i) {
      const Eigen::Vector2d raw((cal.width - 1) * i / 8.0, (cal.height - 1) * v);
      rays.push_back(two_plane_ray(cal.top, cal.bottom, lens.correct(raw)));
    }
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const Ray3& r : rays) {
    const Eigen::Matrix3d m = Eigen::Matrix3d::Identity() - r.direction * r.direction.transpose();
    a += m;
    b += m * r.origin;
  }
  cal.centre = a.ldlt().solve(b);
  double ss = 0;
  for (const Ray3& r : rays) {
    const Eigen::Vector3d d = cal.centre - r.origin;
    ss += (d - d.dot(r.direction) * r.direction).squaredNorm();
  }
  cal.ray_spread_mm = std::sqrt(ss / static_cast<double>(rays.size()));
  // Looking from the centre towards the middle of the frame.
  cal.forward = (Eigen::Vector3d(0, 0.5 * frame.top_height, 0) - cal.centre).normalized();
  if (!cal.centre.allFinite()) return failed_precondition("camera '" + camera_id + "': the camera's rays do not meet");
  return cal;
}

}  // namespace bodyscan
