// The arms' rules: each arm followed cut by cut from the armpit to the hand, its
// axis, elbow and wrist, the upper-arm and wrist girths, the outer arm length, and
// the arm's posture (abduction, elbow bend) (docs/measurements.md).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <vector>

#include "recon/measure/rules/body_cuts.hpp"
#include "recon/measure/rules/sheet.hpp"

namespace bodyscan::rules {

// An arm's horizontal cuts, armpit downwards, and the axes of its two segments.
struct ArmAxes {
  std::vector<Eigen::Vector3d> centres;  // the cuts' centroids
  std::vector<double> girths;            // their tapes, mm
  size_t elbow = 0, wrist = 0;           // indices of the bend's and the wrist's cuts
  // Each segment's axis: a point on it and its unit direction (pointing up).
  Eigen::Vector3d upper_centre = Eigen::Vector3d::Zero(), upper_dir = Eigen::Vector3d::UnitY();
  Eigen::Vector3d fore_centre = Eigen::Vector3d::Zero(), fore_dir = Eigen::Vector3d::UnitY();
  // Where the two axes meet (the elbow's centre), and +1 where the hand lies along
  // +fore_dir from it, else -1.
  Eigen::Vector3d elbow_centre = Eigen::Vector3d::Zero();
  double hand = 1;
};

// The arm on `side`, followed down from `arm_apart_y` (where its own loop ends)
// until it ends, thins, or parts into fingers, or past the crotch (`crotch_y`)
// into the leg; its wrist's cut (wrist_cut) and where its axis bends (two lines
// fitted to the centroids, wrist to armpit, split where together they fit best).
// Records the arm's abduction and elbow bend into the sheet's posture. Nothing
// when the arm is too short to follow (under 30 cuts: it lies against the flank,
// which the posture records).
std::optional<ArmAxes> find_arm_axes(const BodyCuts& cuts, MeasurementSheet& sheet, double arm_apart_y, double crotch_y,
                                     Side side);

// The slope of an arm that lies against the flank (find_arm_axes found nothing),
// from its outer side seen from the front: a line fitted to the cuts' outermost
// points on that side below `arm_apart_y`, over the upper arm. A unit direction in
// the frontal plane pointing up the arm, like ArmAxes::upper_dir. Nothing where
// the cuts are too few.
std::optional<Eigen::Vector3d> outer_side_axis(const BodyCuts& cuts, double arm_apart_y, Side side);

// The arm on `side` from its axes: records `wrist_point_<side>` and
// `elbow_point_<side>`, the wrist and upper-arm girths and the outer arm length
// (from `shoulder_point_<side>`).
void measure_arm(const BodyCuts& cuts, MeasurementSheet& sheet, const std::optional<ArmAxes>& axes, Side side);

// The wrist among an arm's horizontal cuts, armpit downwards (`girths`: their tapes,
// mm), as an index: the narrowest in the lower 45 % above the last three cuts. A
// scan can fuse the fingers, so that the arm's track runs on past the palm into
// them, and they are narrower than the wrist. Where the cuts widen by more than
// `palm_rise` over the narrowest above them (the palm), the wrist is the narrowest
// above that rise. Where the forearm narrows a second time nearer the hand, past a
// rise of more than 2 mm and to within 2 mm of the narrowest (a heavy forearm, and
// the narrowest flips between the two with a scan's noise), that second narrow.
// measure_arm passes 0.6 % of the stature.
size_t wrist_cut(const std::vector<double>& girths, double palm_rise);

}  // namespace bodyscan::rules
