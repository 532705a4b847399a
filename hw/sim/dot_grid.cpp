#include "hw/sim/dot_grid.hpp"

#include <tbb/parallel_for.h>

#include <cmath>
#include <optional>
#include <vector>

#include "hw/sim/renderer.hpp"

namespace bodyscan::hw::sim {

DotGridTarget dot_grid_for(const CameraModel& camera, double distance, int cols, double turn_deg) {
  DotGridTarget t;
  const Mat3d& r = camera.world_from_camera();
  t.centre = camera.centre() + distance * r.col(2);
  const double turn = turn_deg * M_PI / 180.0;
  t.u = std::cos(turn) * r.col(0) + std::sin(turn) * r.col(1);
  t.v = -std::sin(turn) * r.col(0) + std::cos(turn) * r.col(1);
  // The image's width at that distance (pinhole), spanned by `cols` dots plus a margin
  // so some dots fall off the edges, as when a person holds a board.
  const double width_mm = distance * camera.width() / camera.fx();
  t.spacing = width_mm / (cols - 1) * 1.1;
  t.cols = cols + 2;
  t.rows = static_cast<int>(std::ceil(t.cols * static_cast<double>(camera.height()) / camera.width())) + 2;
  t.dot_diameter = 0.4 * t.spacing;
  return t;
}

std::vector<DotTruth> dot_grid_truth(const CameraModel& camera, const DotGridTarget& target) {
  std::vector<DotTruth> out;
  for (int row = 0; row < target.rows; ++row)
    for (int col = 0; col < target.cols; ++col) {
      DotTruth d;
      d.col = col;
      d.row = row;
      d.world = target.dot(col, row);
      const auto p = camera.project(d.world);
      if (p) {
        d.pixel = *p;
        d.in_image = camera.in_image(*p);
      }
      out.push_back(d);
    }
  return out;
}

namespace {

// Undistorted normalised coordinates of every pixel corner (x - 0.5, y - 0.5),
// (w + 1) x (h + 1) of them; nullopt where the lens model cannot invert.
std::vector<std::optional<Vec2d>> undistorted_corners(const CameraModel& model) {
  const int w = model.width(), h = model.height();
  std::vector<std::optional<Vec2d>> out(static_cast<size_t>(w + 1) * (h + 1));
  tbb::parallel_for(0, h + 1, [&](int y) {
    for (int x = 0; x <= w; ++x)
      out[static_cast<size_t>(y) * (w + 1) + x] =
          model.undistort({(x - 0.5 - model.cx()) / model.fx(), (y - 0.5 - model.cy()) / model.fy()});
  });
  return out;
}

// The board as a ray through undistorted normalised coordinates (ux, uy) meets it:
// every quantity is linear in (ux, uy, 1), so each is three numbers, and a
// sub-pixel ray costs a few multiplications.
class BoardSeen {
 public:
  BoardSeen(const CameraModel& model, const DotGridTarget& target) : target_(target) {
    const Mat3d& r = model.world_from_camera();
    const Vec3d n = target.u.cross(target.v);
    const Vec3d to_target = target.centre - model.centre();
    for (int i = 0; i < 3; ++i) {
      n_[i] = r.col(i).dot(n);
      u_[i] = r.col(i).dot(target.u);
      v_[i] = r.col(i).dot(target.v);
    }
    to_n_ = to_target.dot(n);
    to_u_ = to_target.dot(target.u);
    to_v_ = to_target.dot(target.v);
    radius2_ = 0.25 * target.dot_diameter * target.dot_diameter;
    half_w_ = 0.5 * (target.cols - 1) * target.spacing + target.spacing;
    half_h_ = 0.5 * (target.rows - 1) * target.spacing + target.spacing;
  }

  // A dot, the white board, or the room past its edge or behind the camera.
  double albedo(double ux, double uy) const {
    constexpr double kRoom = 0.02;
    const double den = n_[0] * ux + n_[1] * uy + n_[2];
    if (!(std::abs(den) > 1e-9 * std::sqrt(ux * ux + uy * uy + 1))) return kRoom;
    const double t = to_n_ / den;
    if (!(t > 0)) return kRoom;
    const double a = t * (u_[0] * ux + u_[1] * uy + u_[2]) - to_u_;
    const double b = t * (v_[0] * ux + v_[1] * uy + v_[2]) - to_v_;
    if (std::abs(a) >= half_w_ || std::abs(b) >= half_h_) return kRoom;
    // Nearest grid node.
    const double fc = a / target_.spacing + 0.5 * (target_.cols - 1);
    const double fr = b / target_.spacing + 0.5 * (target_.rows - 1);
    const double dc = (fc - std::round(fc)) * target_.spacing, dr = (fr - std::round(fr)) * target_.spacing;
    const bool on_grid =
        std::round(fc) >= 0 && std::round(fc) < target_.cols && std::round(fr) >= 0 && std::round(fr) < target_.rows;
    return on_grid && dc * dc + dr * dr < radius2_ ? 0.05 : 0.9;
  }

 private:
  const DotGridTarget& target_;
  double n_[3] = {}, u_[3] = {}, v_[3] = {};
  double to_n_ = 0, to_u_ = 0, to_v_ = 0, radius2_ = 0, half_w_ = 0, half_h_ = 0;
};

}  // namespace

Frame render_dot_grid(const CameraDescription& camera, const SimulationDescription& sim, const DotGridTarget& target,
                      uint64_t frame_number) {
  const CameraModel model = camera.model();
  const int w = camera.width, h = camera.height;
  constexpr int kSub = 4;
  // The sub-pixel rays come from the lens model undistorted once per pixel corner
  // and interpolated across the pixel: the distortion is smooth, so the
  // interpolation moves a sub-pixel ray by far less than a thousandth of a pixel,
  // at a sixteenth of the Newton solves.
  const auto corners = undistorted_corners(model);
  const BoardSeen board(model, target);
  std::vector<float> irradiance(static_cast<size_t>(w) * h);
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const auto& c00 = corners[static_cast<size_t>(y) * (w + 1) + x];
      const auto& c10 = corners[static_cast<size_t>(y) * (w + 1) + x + 1];
      const auto& c01 = corners[static_cast<size_t>(y + 1) * (w + 1) + x];
      const auto& c11 = corners[static_cast<size_t>(y + 1) * (w + 1) + x + 1];
      double sum = 0;
      for (int sy = 0; sy < kSub; ++sy)
        for (int sx = 0; sx < kSub; ++sx) {
          double albedo = 0.02;  // the room, where the lens model does not reach
          if (c00 && c10 && c01 && c11) {
            const double fx = (sx + 0.5) / kSub, fy = (sy + 0.5) / kSub;
            const double w00 = (1 - fx) * (1 - fy), w10 = fx * (1 - fy), w01 = (1 - fx) * fy, w11 = fx * fy;
            albedo = board.albedo(w00 * c00->x() + w10 * c10->x() + w01 * c01->x() + w11 * c11->x(),
                                  w00 * c00->y() + w10 * c10->y() + w01 * c01->y() + w11 * c11->y());
          }
          sum += albedo;
        }
      irradiance[static_cast<size_t>(y) * w + x] = static_cast<float>(sim.room_light * sum / (kSub * kSub));
    }
  });
  Exposure e;
  e.format = camera.pixel_format;
  e.exposure_us = camera.exposure_us;
  e.gain_db = camera.gain_db;
  blur(irradiance, camera.width, camera.height, camera.blur_px);
  return expose(irradiance, camera, e, sim.seed * 7919 + frame_number);
}

}  // namespace bodyscan::hw::sim
