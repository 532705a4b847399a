// The dot-grid target for lens calibration (thesis §3.1.1): a flat white board
// with a square grid of black dots, held in front of one camera and facing it,
// slightly turned in its plane (the calibration must cope with that). The
// simulator renders what the camera sees of it; the true dot positions are for
// tests and accuracy reports only.
#pragma once

#include <vector>

#include "hw/camera.hpp"
#include "hw/camera_model.hpp"
#include "hw/rig_description.hpp"

namespace bodyscan::hw::sim {

struct DotGridTarget {
  Vec3d centre = Vec3d::Zero();                  // world mm
  Vec3d u = Vec3d::UnitX(), v = Vec3d::UnitY();  // the grid's row and column directions (unit)
  double spacing = 30;                           // dot centre to centre, mm
  double dot_diameter = 12;
  int cols = 25, rows = 21;  // dots
  Vec3d dot(int col, int row) const {
    return centre + (col - 0.5 * (cols - 1)) * spacing * u + (row - 0.5 * (rows - 1)) * spacing * v;
  }
};

// A target `distance` mm in front of the camera, square to its optical axis,
// turned `turn_deg` in its plane, with its dots spaced so that `cols` of them
// span the image's width.
DotGridTarget dot_grid_for(const CameraModel& camera, double distance = 800, int cols = 25, double turn_deg = 4);

struct DotTruth {
  int col = 0, row = 0;
  Vec3d world = Vec3d::Zero();
  Vec2d pixel = Vec2d::Zero();  // where the dot's centre images (distorted)
  bool in_image = false;
};
std::vector<DotTruth> dot_grid_truth(const CameraModel& camera, const DotGridTarget& target);

// The frame the camera takes of the target under the room lights (each pixel
// averaged over 4 x 4 sub-pixel rays, so dot edges are anti-aliased as a lens and
// sensor would).
Frame render_dot_grid(const CameraDescription& camera, const SimulationDescription& sim, const DotGridTarget& target,
                      uint64_t frame_number);

}  // namespace bodyscan::hw::sim
