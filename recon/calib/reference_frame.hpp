// The two reference frames as built and measured (thesis §2.1, §3.1.2): the only
// numbers calibration is given. Everything else - where each camera stands, where
// it looks, its lens, where each laser is - calibration finds out.
//
// World frame: mm, Y up, the bottom frame's light centres in Y = 0 and the top
// frame's in Y = top_height; the front and back poles run along X at Z = +depth/2
// and Z = -depth/2 (centre lines); each carries lights at X = light_x on both of its
// Z faces. A camera on the front side (Z > 0) sees per frame the near pole's outer
// face and the far pole's inner face: four lights at a rectangle's corners.
#pragma once

#include <array>

#include <Eigen/Core>

namespace bodyscan {

enum class FrameSide { kFront, kBack };
inline const char* to_string(FrameSide s) { return s == FrameSide::kFront ? "front" : "back"; }

// The poles a camera sees, named from where it stands.
enum class Pole { kNearBottom = 0, kFarBottom = 1, kNearTop = 2, kFarTop = 3 };
inline constexpr std::array<Pole, 4> kPoles = {Pole::kNearBottom, Pole::kFarBottom, Pole::kNearTop, Pole::kFarTop};
inline const char* to_string(Pole p) {
  constexpr const char* names[] = {"near bottom", "far bottom", "near top", "far top"};
  return names[static_cast<int>(p)];
}
inline bool is_top(Pole p) { return p == Pole::kNearTop || p == Pole::kFarTop; }
inline bool is_near(Pole p) { return p == Pole::kNearBottom || p == Pole::kNearTop; }

struct ReferenceFrame {
  double width = 1800;       // X between the side poles' centre lines
  double depth = 1100;       // Z between the front and back poles' centre lines
  double top_height = 2300;  // Y of the top frame's light centres
  double tube = 40;          // side of the square tubing
  std::array<double, 2> light_x = {-700, 700};

  double plane_y(Pole p) const { return is_top(p) ? top_height : 0.0; }
  // Z of the pole face a camera on `side` sees: the near pole's outer face, the far
  // pole's inner face.
  double face_z(Pole p, FrameSide side) const {
    const double sign = side == FrameSide::kFront ? 1.0 : -1.0;
    return is_near(p) ? sign * (0.5 * depth + 0.5 * tube) : -sign * (0.5 * depth - 0.5 * tube);
  }
  // X range of a front or back pole's face between the side poles.
  double pole_half_length() const { return 0.5 * (width - tube); }
  Eigen::Vector3d light(Pole p, FrameSide side, int i) const {
    return {light_x[static_cast<size_t>(i)], plane_y(p), face_z(p, side)};
  }
};

}  // namespace bodyscan
