// How the customer stood, read from the surface in the body's own frame
// (body_frame.hpp), and whether that lies inside the posture the measurement
// rules are written for. A tailor trusts a value only where the posture it was
// taken in is the one its definition assumes; values that depend on a part of
// the posture (the arms, the stance) are flagged when that part lies outside.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace bodyscan {

struct BodyPosture {
  // The facing's angle about the vertical from the rig's front (world +Z) toward
  // world +X, degrees, and where the trunk's centre stood on the floor (world X, Z, mm).
  double turn_deg = 0;
  double position_x_mm = 0, position_z_mm = 0;
  // Left, right: the upper arm's axis (through its horizontal cuts' centres) from
  // the downward vertical, degrees; the elbow's bend between the upper arm's and
  // the forearm's axes (0: straight).
  std::optional<double> arm_abduction_deg[2];
  std::optional<double> elbow_bend_deg[2];
  // Left, right: the arm could not be followed down from the armpit as a part of
  // its own (it lies against the flank); its angles are then unknown.
  bool arm_against_body[2] = {false, false};
  // The distance between the legs' centres at ankle height (5 % of the stature), mm.
  std::optional<double> ankle_distance_mm;
  // The head's axis (the centres of its cuts from the neck to the crown) from the
  // vertical: forward (+) or back, and toward the body's left (+) or right, degrees.
  std::optional<double> head_tilt_deg, head_side_tilt_deg;
};

// The scanning posture the rules assume (docs/measurements.md, "Posture"): the
// range of each part within which every value that depends on it holds.
struct PostureRange {
  double arm_min_deg = 35, arm_max_deg = 50;
  double ankles_min_mm = 300, ankles_max_mm = 450;
  double head_max_deg = 15;
  double turn_max_deg = 30;  // the rig's cameras see the body best facing the front
};
inline constexpr PostureRange kScanningPosture{};

// One part of the posture, checked: `part` is "arm_left", "arm_right", "feet",
// "head" or "turn"; `message` says what to ask of the customer when not ok.
struct PostureCheck {
  std::string part;
  bool ok = true;
  std::string message;
};

// Every part found, checked against `range`; a part not found is not checked,
// but an arm against the body fails its check.
std::vector<PostureCheck> check_posture(const BodyPosture& posture, const PostureRange& range = kScanningPosture);

// The parts of the posture a measurement of the automatic set depends on, by its
// name ("arm_left", "arm_right", "feet"); empty when none.
std::vector<std::string> posture_parts(const std::string& measurement);

// In words, what a measurement assumes of the posture (for its definition); "" when nothing.
std::string posture_assumed(const std::string& measurement, const PostureRange& range = kScanningPosture);

}  // namespace bodyscan
