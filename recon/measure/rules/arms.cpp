#include "recon/measure/rules/arms.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <tuple>
#include <utility>

#include "recon/measure/profile.hpp"

namespace bodyscan::rules {

namespace {

// How far below a flat extreme a point still counts as on it, mm.
constexpr double kFlatBand = 3;
// The middle of the forearm's flat minimum is halfway between where the tape has
// grown by this much (mm) either side (flat_bottom_middle).
constexpr double kFlatRiseMm = 3;
// The least bend (radians) between upper arm and forearm at which the elbow is
// where their axes meet.
constexpr double kMinElbowBend = 10 * M_PI / 180;
// The wrist's level along the forearm: the fit's weights reach zero this far either
// side of its vertex, as a fraction of the stature.
constexpr double kWristHalf = 0.014;
// The wrist is this fraction of the stature back toward the elbow from where the
// tape, cut by cut toward the hand, has grown kWristFlareMm (mm) over the forearm's
// narrowest cut.
constexpr double kWristBeforeFlare = 0.01;
constexpr double kWristFlareMm = 7;
// A second narrowing of the forearm's cuts nearer the hand, past a rise of more
// than this (mm) and within this of the narrowest, is the wrist (wrist_cut).
constexpr double kSecondNarrowMm = 2;
// The axes are fitted again to cuts square to them (square_cut_axis): over this
// length of each segment (fractions of the stature), starting this far from the
// elbow, where the cuts across the bend take in both segments.
constexpr double kSquareFromElbow = 0.02;
constexpr double kSquareUpper = 0.07;
constexpr double kSquareFore = 0.08;
constexpr double kSquareStepMm = 4;
constexpr int kSquareRounds = 3;
// An arm against the flank is read from its outer side seen from the front:
// between these fractions of the stature below where it parts from the body.
constexpr double kOuterSideFrom = 0.01;
constexpr double kOuterSideTo = 0.08;
// The arm's horizontal cuts, mm apart.
constexpr double kArmStepMm = 3;
// The cuts across the forearm near the wrist, mm apart.
constexpr double kForearmStepMm = 4;

// The arm's cuts that follow_arm takes, from the armpit down: centroids and tapes.
struct ArmTrack {
  std::vector<Eigen::Vector3d> centres;
  std::vector<double> girths;
};

// Whether fingers part from `arm` in `cut`: another loop within `reach` of it, and
// the arm's tape shrunk by at least half of that loop's since the last cut (the
// last of `girths`, the track's so far; none: any loop near counts).
bool fingers_part(const std::vector<Ring>& cut, const Ring& arm, double reach, const std::vector<double>& girths) {
  for (const Ring& r : cut)
    if (&r != &arm && r.girth >= kMinPartGirthMm && (r.centroid - arm.centroid).norm() < reach &&
        (girths.empty() || girths.back() - arm.girth >= 0.5 * r.girth))
      return true;
  return false;
}

// The arm's horizontal cuts from just below where its own loop ends, down to where
// it ends, splits into fingers, thins under 40 % of its largest, or (past the
// crotch) nears the leg: each cut's centroid and tape. The first cut's arm is the
// outermost loop on its side; each next one the loop on that side nearest the last
// centre (a fold of the surface beside the arm can be a small loop farther out).
// Fingers part where another loop lies near the arm's and the arm's own tape has
// shrunk by at least half of that loop's since the last cut (the fingers left it);
// a fold beside the arm adds a loop and takes nothing from the arm's.
ArmTrack follow_arm(const BodyCuts& cuts, double arm_apart_y, double crotch_y, Side side) {
  const double mid_x = cuts.midline_x(), stature = cuts.stature();
  ArmTrack track;
  cuts.prefetch(arm_apart_y - kArmStepMm, crotch_y - 0.05 * stature, -kArmStepMm);  // where a hanging arm ends
  for (double y = arm_apart_y - kArmStepMm; y > 0; y -= kArmStepMm) {
    const std::vector<Ring>& cut = cuts.at(y);
    const Ring* a = track.centres.empty() ? side_ring(cut, mid_x, side, true)
                                          : nearest_side_ring(cut, mid_x, side, track.centres.back());
    if (!a || (y < crotch_y && std::abs(a->centroid.x() - mid_x) < 0.1 * stature)) break;
    if (fingers_part(cut, *a, 0.06 * stature, track.girths)) break;
    if (!track.girths.empty() && a->girth < 0.4 * *std::max_element(track.girths.begin(), track.girths.end())) break;
    track.centres.push_back(a->centroid);
    track.girths.push_back(a->girth);
  }
  return track;
}

Eigen::Vector3d on_axis(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, const Eigen::Vector3d& p) {
  return origin + (p - origin).dot(dir) * dir;
}

// A girth perpendicular to `axis` through p, if it is a loop round p no longer than
// a quarter of the stature (a wrist's, not a neighbour's).
StatusOr<Girth> limb_cut(const BodyCuts& cuts, const Eigen::Vector3d& p, const Eigen::Vector3d& axis,
                         const std::vector<uint32_t>& triangles) {
  StatusOr<Girth> g = mesh_girth(cuts.mesh(), Plane{p, axis}, p, &triangles);
  if (!g.ok()) return g;
  if (!winds_round(g->loop, p, axis) || g->value_mm > 0.25 * cuts.stature())
    return not_found("the cut is not the wrist's alone");
  return g;
}

// The wrist along the forearm's axis (`forearm`, through `wrist_c`, the horizontal
// cuts' narrowest): the narrowest perpendicular cut within 3 % of the stature
// either side (an inclined forearm blurs the horizontal ones), read at a stable
// level. `hand` is +1 where the hand lies along +forearm from the elbow, else -1.
// Moves *wrist_c to the wrist and returns its cut.
StatusOr<Girth> wrist_girth(const BodyCuts& cuts, const Eigen::Vector3d& forearm, double hand,
                            Eigen::Vector3d* wrist_c) {
  const double stature = cuts.stature();
  const std::vector<uint32_t> triangles = cuts.triangles_near(*wrist_c, 0.07 * stature);
  std::vector<double> gs, ts;  // the cuts' tapes and offsets along the forearm from wrist_c
  std::vector<Girth> found;
  std::vector<double> offsets;
  for (double t = -0.03 * stature; t <= 0.03 * stature; t += kForearmStepMm) offsets.push_back(t);
  const std::vector<std::vector<uint32_t>> crossing =
      triangles_by_plane(cuts.mesh(), triangles, *wrist_c, forearm, offsets);
  for (size_t k = 0; k < offsets.size(); ++k) {
    StatusOr<Girth> g = limb_cut(cuts, *wrist_c + offsets[k] * forearm, forearm, crossing[k]);
    if (!g.ok()) continue;
    gs.push_back(g->value_mm);
    found.push_back(std::move(*g));
    ts.push_back(offsets[k]);
  }
  if (gs.empty()) return not_found("no loop round the wrist");
  // Along the forearm the tape is flat over 10-20 mm at its narrowest, and its
  // narrowest cut moves along the arm with the skin's noise. The hand's side is
  // steep: the wrist is kWristBeforeFlare of the stature back from where the tape,
  // cut by cut toward the hand, has grown kWristFlareMm over the narrowest cut (past
  // the window's end if need be). Where no flare is reached, the vertex of a
  // parabola whose weights fall to zero kWristHalf of the stature either side of
  // the vertex itself; where that fit fails, the middle of the flat minimum.
  const size_t low = arg_extreme(gs, false);
  std::optional<double> t = settled_vertex(ts, gs, low, kWristHalf * stature, true);
  if (!t) t = flat_bottom_middle(ts, gs, low, kFlatRiseMm);
  {
    const double flare = gs[low] + kWristFlareMm;
    std::vector<double> ht, hg;  // from the narrowest cut toward the hand
    for (size_t i = low;; i = hand > 0 ? i + 1 : i - 1) {
      ht.push_back(ts[i]), hg.push_back(gs[i]);
      if (hand > 0 ? i + 1 >= ts.size() : i == 0) break;
    }
    for (double tt = ht.back() + hand * kForearmStepMm; std::abs(tt) <= 0.055 * stature && hg.back() < flare;
         tt += hand * kForearmStepMm) {
      StatusOr<Girth> g = limb_cut(cuts, *wrist_c + tt * forearm, forearm, triangles);
      if (!g.ok()) continue;
      ht.push_back(tt), hg.push_back(g->value_mm);
    }
    for (size_t i = 0; i + 1 < ht.size(); ++i)
      if (hg[i + 1] >= flare) {
        t = ht[i] + (flare - hg[i]) / (hg[i + 1] - hg[i]) * (ht[i + 1] - ht[i]) - hand * kWristBeforeFlare * stature;
        break;
      }
  }
  if (t) {
    const Eigen::Vector3d p = *wrist_c + *t * forearm;
    if (StatusOr<Girth> at = limb_cut(cuts, p, forearm, triangles); at.ok()) {
      *wrist_c = p;
      return at;
    }
  }
  const size_t k = settle(gs, arg_extreme(gs, false), 1.0);
  *wrist_c += ts[k] * forearm;
  return std::move(found[k]);
}

// The upper arm's girth perpendicular to its axis halfway between the shoulder
// point and the elbow. Close to the armpit the cut can reach the chest: then it
// slides toward the elbow until its loop is the arm's alone (winds round the axis,
// and reaches no farther than 5 % of the stature from its own centre). Every cut's
// triangles come from one search round the whole slide.
StatusOr<Girth> upper_arm_girth(const BodyCuts& cuts, const Eigen::Vector3d& mid, const Eigen::Vector3d& upper_arm) {
  const double stature = cuts.stature();
  const double cut_radius = 0.07 * stature, slide = 0.08 * stature;
  const std::vector<uint32_t> slide_tris = cuts.triangles_near(mid, cut_radius + slide);
  for (double off = 0; off <= slide; off += 4) {
    const Eigen::Vector3d p = mid - off * upper_arm;
    // Cut within reach of the axis only: a loop running out of it is open, so the
    // chest never joins.
    const std::vector<uint32_t> near_p = cuts.triangles_near(p, cut_radius, slide_tris);
    StatusOr<Girth> g = mesh_girth(cuts.mesh(), Plane{p, upper_arm}, p, &near_p);
    if (!g.ok() || !winds_round(g->loop, p, upper_arm)) continue;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& q : g->loop) centre += q;
    centre /= static_cast<double>(g->loop.size());
    double reach = 0;
    for (const Eigen::Vector3d& q : g->loop) reach = std::max(reach, (q - centre).norm());
    if (reach < 0.05 * stature) return g;
  }
  return not_found("the cut never clears the chest");
}

// The line through the centres of cuts square to `dir`, taken along it from
// `elbow` between `from` and `from + length` (mm), each the limb's own loop
// (winds round the line, reaches no farther than 5 % of the stature from its
// centre); the walk ends at the first cut that is not, past the first that is.
// Horizontal cuts of a tapering limb centre off its axis by an amount that
// changes with the limb's slope; cuts square to the axis meet the same skin
// however the arm is raised. Nothing under five cuts.
std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> square_cut_axis(const BodyCuts& cuts,
                                                                           const Eigen::Vector3d& elbow,
                                                                           const Eigen::Vector3d& dir, double from,
                                                                           double length,
                                                                           const std::vector<uint32_t>& triangles) {
  const double reach_limit = 0.05 * cuts.stature();
  std::vector<double> offsets;
  for (double t = from; t <= from + length; t += kSquareStepMm) offsets.push_back(t);
  const std::vector<std::vector<uint32_t>> crossing = triangles_by_plane(cuts.mesh(), triangles, elbow, dir, offsets);
  std::vector<Eigen::Vector3d> centres;
  for (size_t k = 0; k < offsets.size(); ++k) {
    const Eigen::Vector3d p = elbow + offsets[k] * dir;
    StatusOr<Girth> g = mesh_girth(cuts.mesh(), Plane{p, dir}, p, &crossing[k]);
    bool own = g.ok() && !g->loop.empty() && winds_round(g->loop, p, dir);
    if (own) {
      const Eigen::Vector3d centre = loop_centre(g->loop);
      double reach = 0;
      for (const Eigen::Vector3d& q : g->loop) reach = std::max(reach, (q - centre).norm());
      own = reach < reach_limit;
      if (own) centres.push_back(centre);
    }
    if (!own && !centres.empty()) break;
  }
  if (centres.size() < 5) return std::nullopt;
  // The walk's end moves a cut at a time with the skin (where the limb meets the
  // armpit or the hand): the last third's weights fall to zero toward it, so the
  // line does not jump when one cut more or less is its own.
  const double n = static_cast<double>(centres.size()), taper = n / 3;
  std::vector<double> weights(centres.size());
  for (size_t i = 0; i < centres.size(); ++i) weights[i] = std::min(1.0, (n - static_cast<double>(i)) / taper);
  return fit_line(centres, 0, centres.size(), nullptr, &weights);
}

// Where the upper arm's axis passes closest to the forearm's; c_e's place on the
// upper arm's axis when the arm is nearly straight (no meeting point to speak of)
// or the lines meet farther than 3 % of the stature from it.
Eigen::Vector3d elbow_centre(const ArmAxes& arm, const Eigen::Vector3d& c_e, double stature) {
  const Eigen::Vector3d &uc = arm.upper_centre, &ud = arm.upper_dir;
  const Eigen::Vector3d &fc = arm.fore_centre, &fd = arm.fore_dir;
  const Eigen::Vector3d at = on_axis(uc, ud, c_e);
  if (const double cross = 1 - std::pow(ud.dot(fd), 2); cross > std::pow(std::sin(kMinElbowBend), 2)) {
    const Eigen::Vector3d w0 = uc - fc;
    const Eigen::Vector3d meet = uc + (ud.dot(fd) * fd.dot(w0) - ud.dot(w0)) / cross * ud;
    if ((meet - at).norm() < 0.03 * stature) return meet;
  }
  return at;
}

}  // namespace

std::optional<Eigen::Vector3d> outer_side_axis(const BodyCuts& cuts, double arm_apart_y, Side side) {
  const double mid_x = cuts.midline_x(), stature = cuts.stature(), s = sign(side);
  const double top = arm_apart_y - kOuterSideFrom * stature, bottom = arm_apart_y - kOuterSideTo * stature;
  cuts.prefetch(top, bottom, -kArmStepMm);
  // Least squares x = a + b y over the cuts' outermost points on the side.
  double n = 0, sy = 0, sx = 0, syy = 0, sxy = 0;
  for (double y = top; y >= bottom; y -= kArmStepMm) {
    double out = -std::numeric_limits<double>::infinity();
    for (const Ring& r : cuts.at(y))
      for (const Eigen::Vector3d& q : r.points) out = std::max(out, s * (q.x() - mid_x));
    if (!std::isfinite(out)) continue;
    const double x = mid_x + s * out;
    n += 1, sy += y, sx += x, syy += y * y, sxy += x * y;
  }
  const double spread = n * syy - sy * sy;
  if (n < 10 || spread <= 0) return std::nullopt;
  const double slope = (n * sxy - sx * sy) / spread;  // dx/dy
  return Eigen::Vector3d(slope, 1, 0).normalized();
}

std::optional<ArmAxes> find_arm_axes(const BodyCuts& cuts, MeasurementSheet& sheet, double arm_apart_y, double crotch_y,
                                     Side side) {
  ArmTrack track = follow_arm(cuts, arm_apart_y, crotch_y, side);
  if (track.centres.size() < 30) {
    sheet.posture().arm_against_body[side == Side::kLeft ? 0 : 1] = true;
    return std::nullopt;
  }
  ArmAxes arm;
  arm.centres = std::move(track.centres);
  arm.girths = std::move(track.girths);
  const std::vector<Eigen::Vector3d>& c = arm.centres;
  // Wrist: the narrowest cut in the lower part of the arm, above the palm.
  const size_t w = settle(arm.girths, wrist_cut(arm.girths, 0.006 * cuts.stature()), 1.0);
  size_t e = w / 2;
  double best = std::numeric_limits<double>::infinity();
  for (size_t k = w / 5; k < w * 4 / 5; ++k) {
    double r1 = 0, r2 = 0;
    fit_line(c, 0, k + 1, &r1);
    fit_line(c, k, w + 1, &r2);
    if (r1 + r2 < best) best = r1 + r2, e = k;
  }
  arm.wrist = w, arm.elbow = e;
  std::tie(arm.upper_centre, arm.upper_dir) = fit_line(c, 0, e + 1);
  std::tie(arm.fore_centre, arm.fore_dir) = fit_line(c, e, w + 1);
  arm.hand = (c[w] - c[e]).dot(arm.fore_dir) > 0 ? 1 : -1;
  // The elbow: where the axes meet, cut square to them. Horizontal cuts of a
  // tapering limb centre off its axis by an amount that changes with the limb's
  // slope, and the meeting point of their lines slides along a heavy arm as it is
  // raised; cuts square to each segment's axis, away from the bend, meet the same
  // skin however the arm is held. Each round cuts square to the last round's
  // lines, from the last round's meeting point. The lines themselves stay the
  // horizontal cuts' (fitted over the whole segment, they are steadier under the
  // skin's noise, and the shoulder rule reads the arm's slope from them).
  const double stature = cuts.stature();
  arm.elbow_centre = elbow_centre(arm, c[e], stature);
  const std::vector<uint32_t> triangles =
      cuts.triangles_near(arm.elbow_centre, (kSquareFromElbow + std::max(kSquareUpper, kSquareFore) + 0.05) * stature);
  ArmAxes square = arm;
  for (int round = 0; round < kSquareRounds; ++round) {
    const auto upper = square_cut_axis(cuts, square.elbow_centre, square.upper_dir, kSquareFromElbow * stature,
                                       kSquareUpper * stature, triangles);
    const auto fore = square_cut_axis(cuts, square.elbow_centre, square.hand * square.fore_dir,
                                      kSquareFromElbow * stature, kSquareFore * stature, triangles);
    if (!upper || !fore) break;
    std::tie(square.upper_centre, square.upper_dir) = *upper;
    std::tie(square.fore_centre, square.fore_dir) = *fore;
    square.hand = (c[w] - square.elbow_centre).dot(square.fore_dir) > 0 ? 1 : -1;
    square.elbow_centre = elbow_centre(square, square.elbow_centre, stature);
  }
  arm.elbow_centre = square.elbow_centre;
  const size_t index = side == Side::kLeft ? 0 : 1;
  sheet.posture().arm_abduction_deg[index] = std::acos(std::clamp(arm.upper_dir.y(), -1.0, 1.0)) * 180 / M_PI;
  sheet.posture().elbow_bend_deg[index] =
      std::acos(std::min(1.0, std::abs(arm.upper_dir.dot(arm.fore_dir)))) * 180 / M_PI;
  return arm;
}

void measure_arm(const BodyCuts& cuts, MeasurementSheet& sheet, const std::optional<ArmAxes>& axes, Side side) {
  const std::string sd = side_name(side);
  const double stature = cuts.stature();
  if (!axes) {
    sheet.skip("upper_arm_girth_" + sd, "the " + sd + " arm is too short to follow");
    return;
  }
  const std::vector<Eigen::Vector3d>& c = axes->centres;
  const size_t w = axes->wrist;
  const Eigen::Vector3d &uc = axes->upper_centre, &ud = axes->upper_dir;
  const Eigen::Vector3d &fc = axes->fore_centre, &fd = axes->fore_dir;
  const Eigen::Vector3d elbow_c = axes->elbow_centre;
  Eigen::Vector3d wrist_c = on_axis(fc, fd, c[w]);
  // Outward: across the arm, in the frontal plane, away from the body.
  auto outward = [&](const Eigen::Vector3d& d) {
    Eigen::Vector3d o = -Eigen::Vector3d::UnitZ().cross(d);
    if (sign(side) * o.x() < 0) o = -o;
    return o.normalized().eval();
  };
  // A cut's outer point: where the ray from its centre straight out leaves it (the
  // middle of a limb's flat outer side slides round it with the skin's noise; the
  // ray's crossing moves as far as the skin does). The flat side's middle stays
  // for a cut the ray misses.
  auto outer_point = [&](const Girth& g, const Eigen::Vector3d& axis, const Eigen::Vector3d& out) {
    const Eigen::Vector3d across = axis.cross(out).normalized();
    if (std::optional<Eigen::Vector3d> p = ray_exit(g.loop, loop_centre(g.loop), out, across)) return *p;
    return middle_of_extreme(g.loop, out, across, kFlatBand);
  };
  const StatusOr<Girth> wg = wrist_girth(cuts, fd, axes->hand, &wrist_c);
  const std::vector<uint32_t> elbow_tris = cuts.triangles_near(elbow_c, 0.08 * stature);
  const StatusOr<Girth> eg = mesh_girth(cuts.mesh(), Plane{elbow_c, ud}, elbow_c, &elbow_tris);
  const Eigen::Vector3d wrist_p = wg.ok() && !wg->loop.empty() ? outer_point(*wg, fd, outward(fd)) : wrist_c;
  const Eigen::Vector3d elbow_p = eg.ok() && !eg->loop.empty() ? outer_point(*eg, ud, outward(ud)) : elbow_c;
  sheet.landmark("wrist_point_" + sd, wrist_p);
  sheet.landmark("elbow_point_" + sd, elbow_p);
  sheet.girth("wrist_girth_" + sd, "Wrist girth (" + sd + ")", "5.3.19", wg, {"wrist_point_" + sd},
              "the narrowest cut above the hand, perpendicular to the forearm's axis");
  const Eigen::Vector3d shoulder = sheet.position("shoulder_point_" + sd);
  sheet.girth("upper_arm_girth_" + sd, "Upper-arm girth (" + sd + ")", "5.3.16",
              upper_arm_girth(cuts, on_axis(uc, ud, 0.5 * (shoulder + elbow_c)), ud),
              {"shoulder_point_" + sd, "elbow_point_" + sd},
              "perpendicular to the upper arm's axis, halfway between shoulder point and elbow (moved toward the "
              "elbow until the cut clears the chest)");
  sheet.surface("outer_arm_length_" + sd, "Outer arm length (" + sd + ")", "5.7.8", {shoulder, elbow_p, wrist_p},
                {"shoulder_point_" + sd, "elbow_point_" + sd, "wrist_point_" + sd},
                "over the skin from the shoulder point by the elbow's outer side to the wrist");
}

size_t wrist_cut(const std::vector<double>& g, double palm_rise) {
  const size_t n = g.size();
  if (n < 4) return 0;
  const size_t from = std::min(n * 55 / 100, n - 4);
  size_t w = n - 4;
  for (size_t i = from; i + 3 < n; ++i)
    if (g[i] < g[w]) w = i;
  // Between there and the narrowest, the largest widening over the narrowest above it.
  size_t low = from, palm = from;
  double rise = 0;
  for (size_t i = from; i < w; ++i) {
    if (g[i] < g[low]) low = i;
    if (g[i] - g[low] > rise) rise = g[i] - g[low], palm = i;
  }
  if (rise > palm_rise)
    w = static_cast<size_t>(
        std::min_element(g.begin() + static_cast<std::ptrdiff_t>(from), g.begin() + static_cast<std::ptrdiff_t>(palm)) -
        g.begin());
  // A heavy forearm narrows twice above the hand, a few cm apart and within a mm or
  // two of each other, and the narrowest flips between them with the skin's noise
  // (the forearm's axis, fitted down to it, and the elbow with it). A second narrow
  // nearer the hand, past a rise of more than kSecondNarrowMm and within that of
  // the first, before the palm, is the wrist.
  size_t second = w;
  bool rose = false;
  for (size_t k = w + 1; k + 3 < n && g[k] - g[w] <= palm_rise; ++k) {
    rose = rose || g[k] - g[w] > kSecondNarrowMm;
    if (rose && g[k] - g[w] <= kSecondNarrowMm && (second == w || g[k] < g[second])) second = k;
  }
  return second;
}

}  // namespace bodyscan::rules
