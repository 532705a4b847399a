// The legs' rules: the knees, the leg girths and heights, and the stance
// (docs/measurements.md).
#pragma once

#include <Eigen/Core>
#include <optional>

#include "recon/measure/body_posture.hpp"
#include "recon/measure/girth.hpp"
#include "recon/measure/rules/body_cuts.hpp"
#include "recon/measure/rules/sheet.hpp"

namespace bodyscan::rules {

// A knee's level and the leg's centre there.
struct Knee {
  double y = 0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
};

// The knee on `side`: the narrowest cut of the leg between calf and thigh (18-36 %
// of the stature), the deepest local minimum if there are several, refined to a
// parabola's vertex. Nothing when the leg is not followed there.
std::optional<Knee> find_knee(const BodyCuts& cuts, Side side);

// The leg on `side`: thigh, knee, mid-thigh, calf and minimum leg girths and the
// knee height. Records `knee_<side>`.
void measure_leg(const BodyCuts& cuts, MeasurementSheet& sheet, double crotch_y,
                 const PerSide<std::optional<Knee>>& knees, Side side);

// The distance between the legs' centres at the ankles, into `posture`.
void read_stance(const BodyCuts& cuts, BodyPosture* posture);

// The level a leg's knee height and mid-thigh read the knee at: standing, both
// knees are at one height, so where the other knee's level (`other_y`, if found)
// lies within 10 mm of this knee's (`own_y`), the two knees' mean; else this knee's
// own. Each knee's level is a shallow girth profile's bottom and moves with a
// scan's noise, the two independently: their mean moves about 1/sqrt(2) as much.
double knee_reading_level(double own_y, std::optional<double> other_y);

// One leg's tape in a horizontal cut where hole filling has bridged the gap between
// the thighs (`ring` spans the midline X = mid_x and crosses it on invented surface
// only, mesh confidence under 0.5 front and back): round the measured skin
// (confidence 0.5 or more) on `side`, in the ring's plane. The tape bridges the
// unseen inner side as a tape bridges any hollow; its min_confidence is the lowest
// on that side, so the girth is flagged as crossing the fill. Nothing where the
// ring crosses the midline on measured skin (the trunk, above the crotch), or keeps
// no measured skin on that side.
std::optional<Girth> bridged_part(const Ring& ring, double mid_x, Side side);

}  // namespace bodyscan::rules
