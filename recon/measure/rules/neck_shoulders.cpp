#include "recon/measure/rules/neck_shoulders.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <vector>

#include "recon/measure/profile.hpp"

namespace bodyscan::rules {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// The middle of the neck's flat minimum is halfway between where the tape has
// grown by this much (mm) either side (flat_bottom_middle).
constexpr double kNeckFlatRiseMm = 3;
// The neck's base (the side neck points) is where the front outline has flared to
// this many times the radius of the neck's narrowest horizontal tape.
constexpr double kNeckBaseWidth = 1.3;
// How far below the neck's side (mm) at its base a point still counts as on it:
// the side is flat front to back, and a narrower band's parabola followed the skin's
// noise.
constexpr double kNeckSideBand = 5;
// The same for the top of the shoulder, which is broad front to back.
constexpr double kRidgeBand = 10;
// The shoulder's corner without the arm's axis: the fit's weights reach zero this
// far either side of its vertex, as a fraction of the stature.
constexpr double kCornerHalf = 0.04;
// The shoulder point with the arm's axis (arm_side_corner): where the outline's
// normal has turned this share of the way from the shoulder top's slope to the
// arm's outer side, the slope read over this fraction of the stature from the
// neck, and how far (a fraction of the stature) back toward the neck the point
// lies from there. Skinned bodies keep the point on its skin for any share from
// 0.75 to 0.85 and any distance back (docs/measurements.md); the distance puts it
// over the acromion, where the outline's own corner lies with the arms at 42°.
constexpr double kArmSideTurn = 0.8;
constexpr double kShoulderTopStretch = 0.03;
constexpr double kAcromionBack = 0.013;
// How far below the outline's extreme along a normal (mm) it still counts as on it.
constexpr double kArmSideBandMm = 10;
// Columns of the shoulder's top outline, mm wide.
constexpr double kOutlineColumnMm = 3;

// The section of the mesh's edges between heights y_lo and y_hi by vertical planes
// X = mid_x + s * offset(c), c = 0 .. count-1 (offsets ascending and evenly
// spaced), s the side's sign: in each plane, the points where an edge crosses it.
std::vector<std::vector<Eigen::Vector3d>> vertical_sections(const TriangleMesh& mesh, double mid_x, double s,
                                                            double y_lo, double y_hi,
                                                            const std::function<double(size_t)>& offset, size_t count) {
  std::vector<std::vector<Eigen::Vector3d>> column(count);
  const double c_lo = offset(0), c_hi = offset(count - 1), step = count > 1 ? offset(1) - offset(0) : 1;
  for (const auto& t : mesh.triangles)
    for (int e = 0; e < 3; ++e) {
      const Eigen::Vector3d p = mesh.vertices[t[e]].cast<double>(), q = mesh.vertices[t[(e + 1) % 3]].cast<double>();
      if (std::max(p.y(), q.y()) < y_lo || std::min(p.y(), q.y()) > y_hi) continue;
      const double up = s * (p.x() - mid_x), uq = s * (q.x() - mid_x);
      const double lo = std::max(std::min(up, uq), c_lo), hi = std::min(std::max(up, uq), c_hi);
      if (lo > hi || up == uq) continue;
      for (auto c = static_cast<size_t>(std::max(0.0, std::ceil((lo - c_lo) / step))); c < count && offset(c) <= hi;
           ++c) {
        const Eigen::Vector3d x = p + ((offset(c) - up) / (uq - up)) * (q - p);
        if (x.y() >= y_lo && x.y() <= y_hi) column[c].push_back(x);
      }
    }
  return column;
}

// The shoulder's corner on the top outline seen from the front, (u[i], top[i]) from
// the side neck point out (u: mm out from the midline), without the arm's axis:
// the corner bulging above the chord from the neck to where the outline is well
// down the arm (`y_arm`), the vertex of a parabola fitted to the height above the
// chord with weights falling smoothly to zero kCornerHalf of the stature either
// side of the vertex itself (refined_corner). Nothing where no sample lies above
// the chord.
std::optional<double> outline_corner(const std::vector<double>& u, const std::vector<double>& top, double y_arm,
                                     double stature) {
  const auto [k, corner] = refined_corner(u, top, y_arm, kCornerHalf * stature);
  if (k == 0) return std::nullopt;
  return corner;
}

// The shoulder's corner on the same outline, given the upper arm's axis
// (`upper_arm`, unit, pointing up; s the side's sign). Skinned or real, the skin
// over the shoulder's cap turns with the arm, the more the nearer the arm, so a
// corner read from the outline's shape alone slides along the skin as the arm
// comes down. Two steps hold it:
// - Where the outline turns onto the arm: the point whose outward normal has
//   turned kArmSideTurn of the way from the shoulder top's slope (a line through
//   the outline's first kShoulderTopStretch of the stature) to the normal of the
//   arm's outer side (90 degrees less the arm's abduction in the frontal plane).
//   That skin turns with the arm, and the point keeps its place on it.
// - From there back toward the neck along the outline by kAcromionBack of the
//   stature: the top of the shoulder over the acromion.
std::optional<double> arm_side_corner(const std::vector<double>& u, const std::vector<double>& top,
                                      const Eigen::Vector3d& upper_arm, double s, double stature) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0, n = 0;
  for (size_t i = 1; i < u.size() && u[i] <= u[1] + kShoulderTopStretch * stature; ++i)
    sx += u[i], sy += top[i], sxx += u[i] * u[i], sxy += u[i] * top[i], n += 1;
  if (n < 3) return std::nullopt;
  const double top_deg = std::atan(-(n * sxy - sx * sy) / (n * sxx - sx * sx)) * 180 / M_PI;
  const double arm_deg = std::atan2(-s * upper_arm.x(), upper_arm.y()) * 180 / M_PI;
  const double turn = (top_deg + kArmSideTurn * (90 - arm_deg - top_deg)) * M_PI / 180;
  std::vector<Eigen::Vector3d> outline;  // (u, top, 0)
  for (size_t i = 1; i < u.size(); ++i) outline.emplace_back(u[i], top[i], 0);
  const Eigen::Vector3d normal(std::sin(turn), std::cos(turn), 0), along(std::cos(turn), -std::sin(turn), 0);
  const Eigen::Vector3d arm_side = middle_of_extreme(outline, normal, along, kArmSideBandMm, true);
  // Back toward the neck along the outline.
  size_t i = 1;
  while (i + 1 < u.size() && u[i + 1] < arm_side.x()) ++i;
  double left = kAcromionBack * stature, cu = arm_side.x(), cy = arm_side.y();
  for (size_t j = i; j >= 1 && left > 0; --j) {
    const double du = cu - u[j], dy = cy - top[j], step = std::hypot(du, dy);
    if (step >= left) return cu - du * left / step;
    left -= step, cu = u[j], cy = top[j];
  }
  return cu;
}

}  // namespace

StatusOr<NeckLevel> find_neck(const BodyCuts& cuts, MeasurementSheet& sheet, double higher_armpit_y) {
  const double stature = cuts.stature();
  std::vector<double> ys, gs;
  std::vector<Eigen::Vector3d> cs;
  const double y0 = higher_armpit_y + 0.04 * stature, y1 = stature - 0.09 * stature;
  cuts.prefetch(y0, y1, 2);
  for (double y = y0; y <= y1; y += 2)
    if (const Ring* m = cuts.midline_loop(y)) ys.push_back(y), gs.push_back(m->girth), cs.push_back(m->centroid);
  if (ys.empty()) return not_found("measure: no neck found between the armpits and the head");
  // The neck is narrowest over several mm, and the middle of the samples near the
  // narrowest slides with the skin's noise (the tilted neck girth with it); the
  // middle of the flat minimum moves less. That run's middle is the fallback.
  NeckLevel neck;
  const size_t k = arg_extreme(gs, false), mid = settle(gs, k, 1.0);
  neck.y = ys[mid], neck.centre = cs[mid];
  if (const std::optional<double> y = flat_bottom_middle(ys, gs, k, kNeckFlatRiseMm))
    if (const Ring* m = cuts.midline_loop(*y)) neck.y = *y, neck.centre = m->centroid;
  // The narrowest tape is flat over several mm, so its length holds still where
  // its level slides.
  neck.radius = gs[k] / (2 * M_PI);
  sheet.landmark("neck_level", neck.centre);
  return neck;
}

Status find_side_neck_point(const BodyCuts& cuts, MeasurementSheet& sheet, const NeckLevel& neck,
                            double higher_armpit_y, Side side) {
  // The neck's base on this side: the level where the front outline (the midline
  // loop's half-width on that side) has flared to kNeckBaseWidth times the radius
  // of the neck's narrowest horizontal tape, interpolated between cuts.
  const double mid_x = cuts.midline_x(), s = sign(side);
  const double target = kNeckBaseWidth * neck.radius;
  double y_prev = neck.y, w_prev = -kInf, y_base = kInf;
  cuts.prefetch(neck.y, higher_armpit_y, -2);
  for (double y = neck.y; y > higher_armpit_y && y_base == kInf; y -= 2) {
    const Ring* m = cuts.midline_loop(y);
    if (!m) break;
    double w = -kInf;
    for (const Eigen::Vector3d& p : m->points) w = std::max(w, s * (p.x() - mid_x));
    if (w >= target) y_base = w_prev == -kInf ? y : y_prev + (target - w_prev) / (w - w_prev) * (y - y_prev);
    y_prev = y, w_prev = w;
  }
  if (y_base == kInf) return not_found("measure: no " + side_name(side) + " shoulder below the neck");
  const Ring* m = cuts.midline_loop(y_base);
  if (!m) return not_found("measure: no " + side_name(side) + " side of the neck at its base");
  sheet.landmark("side_neck_point_" + side_name(side),
                 middle_of_extreme(m->points, {s, 0, 0}, Eigen::Vector3d::UnitZ(), kNeckSideBand));
  return Status();
}

Status find_shoulder_point(const BodyCuts& cuts, MeasurementSheet& sheet, double arm_apart_y,
                           const std::optional<Eigen::Vector3d>& upper_arm, Side side) {
  const double mid_x = cuts.midline_x(), stature = cuts.stature(), s = sign(side);
  const std::string name = "shoulder_point_" + side_name(side);
  const Eigen::Vector3d side_neck = sheet.position("side_neck_point_" + side_name(side));
  const double neck_out = s * (side_neck.x() - mid_x);
  // Up to just above the side neck point (the head overhangs the neck's side).
  const double y_hi = side_neck.y() + 0.01 * stature;
  const double u0 = neck_out + 0.01 * stature, u1 = neck_out + 0.25 * stature;
  const auto columns = static_cast<size_t>((u1 - u0) / kOutlineColumnMm) + 1;
  // The top outline seen from the front, exact on the mesh: the highest point of
  // the section in each column's central plane (a column's highest vertex drops
  // wherever a coarse mesh has no vertex near the top). u: out from the midline.
  const std::vector<std::vector<Eigen::Vector3d>> column = vertical_sections(
      cuts.mesh(), mid_x, s, arm_apart_y, y_hi, [&](size_t c) { return u0 + (c + 0.5) * kOutlineColumnMm; }, columns);
  std::vector<double> us = {neck_out}, tops = {side_neck.y()};
  const double y_arm = arm_apart_y + 0.25 * (side_neck.y() - arm_apart_y);  // well down the arm
  for (size_t c = 0; c < columns && tops.back() > y_arm; ++c) {
    if (column[c].empty()) continue;
    double top = -kInf;
    for (const Eigen::Vector3d& x : column[c]) top = std::max(top, x.y());
    us.push_back(u0 + (c + 0.5) * kOutlineColumnMm), tops.push_back(top);
  }
  if (us.size() < 4) return not_found("measure: no " + side_name(side) + " shoulder outline");
  const std::optional<double> corner =
      upper_arm ? arm_side_corner(us, tops, *upper_arm, s, stature) : outline_corner(us, tops, y_arm, stature);
  if (!corner) {
    sheet.landmark(name, side_neck);
    return Status();
  }
  // The top of the shoulder runs front to back: its middle there, between the
  // section's points.
  const double u = *corner;
  const std::vector<std::vector<Eigen::Vector3d>> at_corner = vertical_sections(
      cuts.mesh(), mid_x, s, arm_apart_y, y_hi, [u](size_t) { return u; }, 1);
  const std::vector<Eigen::Vector3d>& top =
      at_corner[0].empty()
          ? column[std::min(columns - 1, static_cast<size_t>(std::max(0.0, (u - u0) / kOutlineColumnMm)))]
          : at_corner[0];
  if (top.empty()) {
    sheet.landmark(name, side_neck);
    return Status();
  }
  sheet.landmark(name, middle_of_extreme(top, Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), kRidgeBand, true));
  return Status();
}

void find_neck_points(const BodyCuts& cuts, MeasurementSheet& sheet, const NeckLevel& neck) {
  const double mid_x = cuts.midline_x(), stature = cuts.stature();
  const double y_side_neck =
      0.5 * (sheet.position("side_neck_point_left").y() + sheet.position("side_neck_point_right").y());
  double f = neck.centre.z(), b = neck.centre.z();
  if (const Ring* m = cuts.midline_loop(y_side_neck)) m->crossing_z(mid_x, &f, &b);
  sheet.landmark("back_neck_point", {mid_x, y_side_neck, b});
  std::vector<Eigen::Vector2d> curve;  // (y, front z), top down
  cuts.prefetch(neck.y, y_side_neck - 0.08 * stature, -2);
  for (double y = neck.y; y >= y_side_neck - 0.08 * stature; y -= 2) {
    double fz = 0, bz = 0;
    const Ring* m = cuts.midline_loop(y);
    if (m && m->crossing_z(mid_x, &fz, &bz)) curve.emplace_back(y, fz);
  }
  Eigen::Vector3d front(mid_x, y_side_neck - 0.03 * stature, neck.centre.z());
  if (curve.size() >= 3) {
    // The notch: the front's deepest point behind the chord from neck to chest. The
    // profile's bottom is flat, and its deepest sample follows the skin's noise:
    // refined to the vertex of a parabola fitted to the depth over 2 % of the
    // stature either side.
    const Notch notch = deepest_behind_chord(curve, 0.02 * stature);
    front = {mid_x, curve[notch.k].x(), curve[notch.k].y()};
    if (const std::optional<double> yv = notch.vertex_y) {
      for (size_t i = 0; i + 1 < curve.size(); ++i)
        if (curve[i].x() >= *yv && *yv >= curve[i + 1].x()) {
          const double t = (curve[i].x() - *yv) / (curve[i].x() - curve[i + 1].x());
          front = {mid_x, *yv, curve[i].y() + t * (curve[i + 1].y() - curve[i].y())};
        }
    }
  }
  sheet.landmark("front_neck_point", front);
}

void measure_neck(const BodyCuts& cuts, MeasurementSheet& sheet, const NeckLevel& neck) {
  // The smallest loop round the neck over planes tilted forward and back: the one
  // perpendicular to the neck's axis.
  {
    const std::vector<uint32_t> tris = cuts.triangles_near(neck.centre, 0.08 * cuts.stature());
    StatusOr<Girth> best = not_found("no loop round the neck");
    double best_tilt = 0;
    auto cut = [&](double deg) {
      const double t = deg * M_PI / 180;
      Plane p{neck.centre, Eigen::Vector3d(0, std::cos(t), std::sin(t))};
      StatusOr<Girth> g = mesh_girth(cuts.mesh(), p, neck.centre, &tris);
      // Only a loop round the neck counts (a steep cut can leave the part of the
      // mesh searched, and a scrap of ear or chin would win).
      if (g.ok() && winds_round(g->loop, neck.centre, p.normal) && (!best.ok() || g->value_mm < best->value_mm))
        best = std::move(g), best_tilt = deg;
    };
    for (double d = -40; d <= 40; d += 4) cut(d);
    const double coarse = best_tilt;
    for (double d = coarse - 3; d <= coarse + 3; d += 1) cut(d);
    sheet.girth("neck_girth", "Neck girth", "5.3.2", best, {"neck_level"},
                "smallest girth round the neck, over planes through its narrowest level tilted up to 40 degrees "
                "forward or back (perpendicular to the neck's axis)");
  }
  // Neck base: the tape round the neck's base through its four points.
  const std::vector<Eigen::Vector3d> via = {sheet.position("back_neck_point"), sheet.position("side_neck_point_left"),
                                            sheet.position("front_neck_point"), sheet.position("side_neck_point_right"),
                                            sheet.position("back_neck_point")};
  sheet.surface("neck_base_girth", "Neck base girth", "5.3.3", via,
                {"back_neck_point", "side_neck_point_left", "front_neck_point", "side_neck_point_right"},
                "round the neck's base over the skin through the back, side and front neck points");
  if (BodyMeasurement* m = sheet.last("neck_base_girth")) {
    m->kind = "girth";
    m->closed = true;
  }
}

void measure_across_back(MeasurementSheet& sheet) {
  const Eigen::Vector3d l = sheet.position("shoulder_point_left"), r = sheet.position("shoulder_point_right"),
                        b = sheet.position("back_neck_point");
  sheet.surface("shoulder_width", "Across-back shoulder width", "5.4.3", {r, b, l},
                {"shoulder_point_right", "back_neck_point", "shoulder_point_left"},
                "over the skin from shoulder point to shoulder point by the back neck point");
  BodyMeasurement m;
  m.name = "biacromial_breadth", m.label = "Shoulder breadth (straight)", m.kind = "distance";
  m.value_mm = (l - r).norm();
  m.path = {r, l};
  m.landmarks = {"shoulder_point_right", "shoulder_point_left"};
  m.definition = "straight line between the shoulder points";
  sheet.add(std::move(m));
  sheet.surface("back_neck_to_waist", "Back neck point to waist", "5.4.5", {b, sheet.position("waist_back_point")},
                {"back_neck_point", "waist_back_point"}, "over the skin down the centre back to the waist level");
}

void read_head_tilt(const BodyCuts& cuts, BodyPosture* posture) {
  // A line through the centres of the cranium's cuts, the top 1.5-6 % of the
  // stature: above the face and the jaw, whose shape would tilt the line on a level
  // head.
  std::vector<Eigen::Vector3d> c;
  const double stature = cuts.stature();
  const double y0 = stature - 0.06 * stature, y1 = stature - 0.015 * stature;
  cuts.prefetch(y0, y1, 2);
  for (double y = y0; y <= y1; y += 2)
    if (const Ring* m = cuts.midline_loop(y)) c.push_back(m->centroid);
  if (c.size() < 5) return;
  const Eigen::Vector3d d = fit_line(c, 0, c.size()).second;
  posture->head_tilt_deg = std::atan2(d.z(), d.y()) * 180 / M_PI;
  posture->head_side_tilt_deg = std::atan2(d.x(), d.y()) * 180 / M_PI;
}

}  // namespace bodyscan::rules
