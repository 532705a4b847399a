// The rules for the neck, the shoulders and the head: the neck's level, the side,
// back and front neck points, the shoulder points (acromion stand-ins), the neck
// girths, the lengths across the back, and the head's tilt (docs/measurements.md).
#pragma once

#include <Eigen/Core>
#include <optional>

#include "core/status.hpp"
#include "recon/measure/body_posture.hpp"
#include "recon/measure/rules/body_cuts.hpp"
#include "recon/measure/rules/sheet.hpp"

namespace bodyscan::rules {

// The neck's narrowest stretch.
struct NeckLevel {
  double y = 0;                                      // its middle, mm above the floor
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // the midline loop's centroid there
  double radius = 0;                                 // the narrowest horizontal tape's length / 2 pi
};

// The neck between the higher armpit (+4 % of the stature) and the head (-9 %):
// the middle of its narrowest stretch. Records `neck_level`; errors when no loop
// spans the midline there.
StatusOr<NeckLevel> find_neck(const BodyCuts& cuts, MeasurementSheet& sheet, double higher_armpit_y);

// The side neck point on `side`: where the front outline has flared into the
// shoulder, above the higher armpit. Records `side_neck_point_<side>`.
Status find_side_neck_point(const BodyCuts& cuts, MeasurementSheet& sheet, const NeckLevel& neck,
                            double higher_armpit_y, Side side);

// The shoulder point on `side`: the corner of the shoulder's top outline seen from
// the front, from the side neck point out and down the arm to a quarter of the way
// to `arm_apart_y` (where the arm's own loop ends). With the upper arm's axis
// (`upper_arm`: unit, pointing up), the corner is found where the skin keeps it
// whatever the arm's angle; without, where the outline bends most (which slides
// out along the skin as the arm comes down). Records `shoulder_point_<side>`.
Status find_shoulder_point(const BodyCuts& cuts, MeasurementSheet& sheet, double arm_apart_y,
                           const std::optional<Eigen::Vector3d>& upper_arm, Side side);

// The back neck point (the centre back at the side neck points' level) and the
// front neck point (the notch of the front midline below the neck).
void find_neck_points(const BodyCuts& cuts, MeasurementSheet& sheet, const NeckLevel& neck);

// The neck girth (the smallest over tilted planes through the neck's level) and
// the neck base girth (over the skin through the four neck points).
void measure_neck(const BodyCuts& cuts, MeasurementSheet& sheet, const NeckLevel& neck);

// The shoulder width over the back, the straight shoulder breadth and the back
// neck point to the waist.
void measure_across_back(MeasurementSheet& sheet);

// The head's forward and sideways tilt from the cranium's cuts, into `posture`.
void read_head_tilt(const BodyCuts& cuts, BodyPosture* posture);

}  // namespace bodyscan::rules
