#include "hw/sim/dot_grid.hpp"

#include <tbb/parallel_for.h>

#include <cmath>

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

Frame render_dot_grid(const CameraDescription& camera, const SimulationDescription& sim, const DotGridTarget& target,
                      uint64_t frame_number) {
  const CameraModel model = camera.model();
  const int w = camera.width, h = camera.height;
  const Vec3d n = target.u.cross(target.v);
  const double radius2 = 0.25 * target.dot_diameter * target.dot_diameter;
  const double half_w = 0.5 * (target.cols - 1) * target.spacing + target.spacing;
  const double half_h = 0.5 * (target.rows - 1) * target.spacing + target.spacing;
  constexpr int kSub = 4;
  std::vector<float> irradiance(static_cast<size_t>(w) * h);
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      double sum = 0;
      for (int sy = 0; sy < kSub; ++sy)
        for (int sx = 0; sx < kSub; ++sx) {
          const Vec2d px(x - 0.5 + (sx + 0.5) / kSub, y - 0.5 + (sy + 0.5) / kSub);
          const auto ray = model.ray(px);
          double albedo = 0.02;  // the room behind the board
          if (ray) {
            const double den = ray->dot(n);
            if (std::abs(den) > 1e-9) {
              const double t = (target.centre - model.centre()).dot(n) / den;
              const Vec3d p = model.centre() + t * *ray - target.centre;
              const double a = p.dot(target.u), b = p.dot(target.v);
              if (t > 0 && std::abs(a) < half_w && std::abs(b) < half_h) {
                // Nearest grid node.
                const double fc = a / target.spacing + 0.5 * (target.cols - 1);
                const double fr = b / target.spacing + 0.5 * (target.rows - 1);
                const double dc = (fc - std::round(fc)) * target.spacing, dr = (fr - std::round(fr)) * target.spacing;
                const bool on_grid = std::round(fc) >= 0 && std::round(fc) < target.cols && std::round(fr) >= 0 &&
                                     std::round(fr) < target.rows;
                albedo = on_grid && dc * dc + dr * dr < radius2 ? 0.05 : 0.9;
              }
            }
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
