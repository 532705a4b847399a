#include "recon/measure/body_measurements.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <iterator>
#include <optional>
#include <string_view>

#include "recon/measure/rules/arms.hpp"
#include "recon/measure/rules/body_cuts.hpp"
#include "recon/measure/rules/legs.hpp"
#include "recon/measure/rules/neck_shoulders.hpp"
#include "recon/measure/rules/sheet.hpp"
#include "recon/measure/rules/trunk.hpp"

namespace bodyscan {

const BodyMeasurement* BodyMeasurements::find(const std::string& name) const {
  for (const BodyMeasurement& m : measurements)
    if (m.name == name) return &m;
  return nullptr;
}

const BodyLandmark* BodyMeasurements::landmark(const std::string& name) const {
  for (const BodyLandmark& l : landmarks)
    if (l.name == name) return &l;
  return nullptr;
}

double iso20685_allowance_mm(const BodyMeasurement& m) {
  static const char* const kTorso[] = {"chest_girth", "bust_girth", "underbust_girth",
                                       "waist_girth", "hip_girth",  "max_hip_girth"};
  if (m.kind == "girth") return std::find(std::begin(kTorso), std::end(kTorso), m.name) != std::end(kTorso) ? 9 : 4;
  const std::string_view breadth = "_breadth";
  const bool is_breadth =
      m.name.size() > breadth.size() && m.name.compare(m.name.size() - breadth.size(), breadth.size(), breadth) == 0;
  return m.kind == "height" || is_breadth ? 4 : 5;
}

StatusOr<BodyMeasurements> measure_body(const TriangleMesh& mesh, const BodyMeasureOptions& options) {
  if (mesh.triangles.empty()) return invalid_argument("measure: the mesh has no triangles");
  BodyFrameOptions frame_options;
  frame_options.floor_y = options.floor_y;
  ASSIGN_OR_RETURN(const BodyFrame frame, find_body_frame(mesh, frame_options));
  // The rules read the body in its own frame: facing +Z, its left at +X, standing
  // on Y = 0.
  const TriangleMesh body = transformed(mesh, frame.body_from_world());
  BodyMeasurements out;
  {
    using rules::kBothSides;
    using rules::Side;
    // The sheet starts building the surface paths at once, beside the cuts.
    rules::MeasurementSheet sheet(body, &out);
    rules::BodyCuts cuts(body, frame, options.step_mm);
    if (!(cuts.stature() > 500))
      return invalid_argument("measure: the body is under 500 mm tall; is it a standing body in mm, Y up?");
    RETURN_IF_ERROR(cuts.find_midline());
    ASSIGN_OR_RETURN(const double crotch_y, rules::find_crotch(cuts, sheet));
    rules::PerSide<rules::ArmJoin> arms;
    for (Side side : kBothSides) {
      ASSIGN_OR_RETURN(arms[side], rules::find_arm_join(cuts, sheet, crotch_y, side));
    }
    const double higher_armpit_y = std::max(arms.left.armpit_y, arms.right.armpit_y);
    ASSIGN_OR_RETURN(const rules::NeckLevel neck, rules::find_neck(cuts, sheet, higher_armpit_y));
    for (Side side : kBothSides) RETURN_IF_ERROR(rules::find_side_neck_point(cuts, sheet, neck, higher_armpit_y, side));
    rules::PerSide<std::optional<rules::ArmAxes>> arm_axes;
    for (Side side : kBothSides)
      arm_axes[side] = rules::find_arm_axes(cuts, sheet, arms[side].followed_from_y, crotch_y, side);
    for (Side side : kBothSides) {
      // An arm lost against the flank is read from its outer side, whose slope a
      // heavy arm's bulges tilt outward. It touches the flank, and so hangs no
      // farther out than the other arm where that one is followed clear of the body:
      // the steeper of its outer side and the other's axis, mirrored.
      std::optional<Eigen::Vector3d> upper_arm;
      if (arm_axes[side]) {
        upper_arm = arm_axes[side]->upper_dir;
      } else {
        upper_arm = rules::outer_side_axis(cuts, arms[side].followed_from_y, side);
        if (const auto& other = arm_axes[rules::opposite(side)]) {
          const Eigen::Vector3d mirrored(-other->upper_dir.x(), other->upper_dir.y(), other->upper_dir.z());
          if (!upper_arm || std::abs(mirrored.y()) > std::abs(upper_arm->y())) upper_arm = mirrored;
        }
      }
      RETURN_IF_ERROR(rules::find_shoulder_point(cuts, sheet, arms[side].apart_y, upper_arm, side));
    }
    rules::find_neck_points(cuts, sheet, neck);
    const rules::TrunkLevels levels = rules::find_trunk_levels(cuts, sheet, crotch_y, arms);

    sheet.landmark("top_of_head", cuts.crown());
    sheet.height("stature", "Stature", "5.1.1", {"top_of_head"}, cuts.crown(), "top of the head above the floor");
    // The back neck point lies at the side neck points' level: the value is read
    // from all three.
    sheet.height("cervical_height", "Cervical height", "",
                 {"back_neck_point", "side_neck_point_left", "side_neck_point_right"},
                 sheet.position("back_neck_point"), "back neck point (at the side neck points' level) above the floor");
    sheet.height("crotch_height", "Inside leg length (crotch height)", "5.1.15", {"crotch"}, sheet.position("crotch"),
                 "crotch above the floor");
    rules::measure_neck(cuts, sheet, neck);
    rules::measure_trunk(cuts, sheet, crotch_y, arms, levels);
    rules::PerSide<std::optional<rules::Knee>> knees;
    for (Side side : kBothSides) knees[side] = rules::find_knee(cuts, side);
    for (Side side : kBothSides) rules::measure_leg(cuts, sheet, crotch_y, knees, side);
    for (Side side : kBothSides) rules::measure_arm(cuts, sheet, arm_axes[side], side);
    rules::measure_across_back(sheet);
    rules::read_head_tilt(cuts, &out.posture);
    rules::read_stance(cuts, &out.posture);
  }
  // Back into the mesh's frame.
  const Eigen::Isometry3d& to_world = frame.world_from_body;
  for (BodyLandmark& l : out.landmarks) l.position = to_world * l.position;
  for (BodyMeasurement& m : out.measurements) {
    for (Eigen::Vector3d& p : m.path) p = to_world * p;
    for (Eigen::Vector3d& p : m.loop) p = to_world * p;
    if (m.plane) m.plane = Plane{to_world * m.plane->point, to_world.linear() * m.plane->normal};
  }
  out.floor_y = frame.floor_y;
  out.frame = frame;
  out.posture.turn_deg = frame.turn_deg;
  out.posture.position_x_mm = frame.world_from_body.translation().x();
  out.posture.position_z_mm = frame.world_from_body.translation().z();
  out.posture_checks = check_posture(out.posture);
  for (BodyMeasurement& m : out.measurements) {
    m.posture_assumed = posture_assumed(m.name);
    for (const std::string& part : posture_parts(m.name))
      for (const PostureCheck& c : out.posture_checks)
        if (c.part == part && !c.ok) m.outside_posture = true;
  }
  return out;
}

}  // namespace bodyscan
