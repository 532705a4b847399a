#include "recon/measure/rules/legs.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "recon/measure/body_measurements.hpp"
#include "recon/measure/profile.hpp"

namespace bodyscan::rules {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// The thigh's tape is taken this far (a fraction of the stature) below the crotch
// or lower: right under the crotch the tape grows steeply, and a surface closes the
// thighs' gap a few mm early where they nearly touch.
constexpr double kThighBelowCrotch = 0.015;
// Knees whose levels lie within this (mm) of each other are level: the knee heights
// and the mid-thigh take their mean (knee_reading_level).
constexpr double kLevelKneesMm = 10;
// The ankles' height, a fraction of the stature: the stance is read from the legs'
// centres there.
constexpr double kAnkleLevel = 0.05;

// The leg's loop on `side` in a cut, when it is whole there. Scraps of a cut (a
// toe, a fold of fill) are no leg: at least 6 % of the stature round. A leg cut in
// pieces (a slit a scan can leave behind the ankle splits the heel from the rest)
// is no level to measure at.
const Ring* leg_loop(const BodyCuts& cuts, const std::vector<Ring>& cut, Side side) {
  const Ring* l = side_ring(cut, cuts.midline_x(), side, false, 0.06 * cuts.stature());
  return l && parts_near(cut, *l, 0.06 * cuts.stature()) == 0 ? l : nullptr;
}

// The tape round the points of `ring` on `side` of the midline X = mid_x (with
// `measured_only`, those of mesh confidence 0.5 or more), in the ring's plane: a
// tape round one of two thighs pressed together, or bridged by hole filling, runs
// between them. Its min_confidence is the lowest on that side; loop_length_mm
// counts the edges between kept points. Nothing with fewer than three.
std::optional<Girth> side_tape(const Ring& ring, double mid_x, Side side, bool measured_only) {
  const size_t n = ring.points.size();
  if (n < 3) return std::nullopt;
  const double s = sign(side);
  const double y = ring.points.front().y();
  const auto on_side = [&](size_t i) { return s * (ring.points[i].x() - mid_x) > 0; };
  const auto confidence = [&](size_t i) { return i < ring.confidence.size() ? ring.confidence[i] : 1.0f; };
  const auto kept = [&](size_t i) { return on_side(i) && (!measured_only || confidence(i) >= kMeasuredConfidence); };
  Girth g;
  g.plane = Plane{Eigen::Vector3d(0, y, 0), Eigen::Vector3d::UnitY()};
  g.loops_cut = 1;
  std::vector<Eigen::Vector2d> flat;
  for (size_t i = 0; i < n; ++i) {
    if (!on_side(i)) continue;
    g.min_confidence = std::min(g.min_confidence, confidence(i));
    if (!kept(i)) continue;
    if (kept((i + 1) % n)) g.loop_length_mm += (ring.points[(i + 1) % n] - ring.points[i]).norm();
    g.loop.push_back(ring.points[i]);
    flat.emplace_back(ring.points[i].x(), ring.points[i].z());
  }
  // The tape bridges this side's unseen skin on a hull of the seen: how far the
  // real skin could move it is not known.
  if (g.min_confidence < kMeasuredConfidence) g.fill_bound_mm.reset();
  const std::vector<Eigen::Vector2d> hull = convex_hull(std::move(flat));
  if (hull.size() < 3) return std::nullopt;
  g.value_mm = closed_length(hull);
  for (const Eigen::Vector2d& q : hull) g.tape.emplace_back(q.x(), y, q.y());
  return g;
}

// The thigh's tape at a level below the crotch where a loop spans the midline:
// hole filling bridges the gap between the thighs (bridged_part, round the leg's
// measured skin), or the thighs press together (side_tape). Of the loops spanning
// the midline, this side's own where each leg's loop crosses it (skinned legs
// pass through each other), else the longest (one loop round both). Nothing
// unless the tape is a leg's (6 % of the stature round).
std::optional<Girth> bridged_leg(const BodyCuts& cuts, double crotch_y, double y, Side side) {
  if (y >= crotch_y) return std::nullopt;
  const std::vector<Ring>& cut = cuts.at(y);
  const double mid_x = cuts.midline_x();
  const Ring* m = nullptr;
  for (const Ring& r : cut) {
    if (!r.spans_x(mid_x) || r.girth < 0.06 * cuts.stature()) continue;
    const bool own = sign(side) * (r.centroid.x() - mid_x) > 0;
    const bool m_own = m && sign(side) * (m->centroid.x() - mid_x) > 0;
    if (!m || (own && !m_own) || (own == m_own && r.girth > m->girth)) m = &r;
  }
  if (!m) return std::nullopt;
  std::optional<Girth> g = bridged_part(*m, mid_x, side);
  if (!g) g = side_tape(*m, mid_x, side, false);
  if (!g || g->value_mm < 0.06 * cuts.stature()) return std::nullopt;
  g->loops_cut = cut.size();
  return g;
}

// The leg's largest (or smallest) cut between y0 and y1, in 2 mm steps, settled
// over a flat extreme: its centre, and its level in *y_at (left as it is where no
// cut finds the leg). With `bridged`, a level where the thighs are bridged reads
// the leg's measured skin.
Eigen::Vector3d extreme_cut(const BodyCuts& cuts, double crotch_y, Side side, double y0, double y1, bool largest,
                            double* y_at, bool bridged = false) {
  std::vector<double> ys, gs;
  std::vector<Eigen::Vector3d> cs;
  cuts.prefetch(y0, y1, 2);
  for (double y = y0; y <= y1; y += 2) {
    const std::vector<Ring>& cut = cuts.at(y);
    if (const Ring* l = leg_loop(cuts, cut, side)) {
      ys.push_back(y), gs.push_back(l->girth), cs.push_back(l->centroid);
    } else if (const std::optional<Girth> b = bridged ? bridged_leg(cuts, crotch_y, y, side) : std::nullopt) {
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (const Eigen::Vector3d& p : b->tape) c += p;
      ys.push_back(y), gs.push_back(b->value_mm), cs.push_back(c / static_cast<double>(b->tape.size()));
    }
  }
  if (ys.empty()) return {cuts.midline_x() + sign(side) * 0.05 * cuts.stature(), *y_at, cuts.midline_z()};
  const size_t k = settle(gs, arg_extreme(gs, largest), 1.0);
  *y_at = ys[k];
  return cs[k];
}

}  // namespace

std::optional<Knee> find_knee(const BodyCuts& cuts, Side side) {
  std::vector<double> ys, gs;
  std::vector<Eigen::Vector3d> cs;
  cuts.prefetch(cuts.level(0.18), cuts.level(0.36), 2);
  for (double y = cuts.level(0.18); y <= cuts.level(0.36); y += 2)
    if (const Ring* l = leg_loop(cuts, cuts.at(y), side))
      ys.push_back(y), gs.push_back(l->girth), cs.push_back(l->centroid);
  if (gs.size() < 10) return std::nullopt;
  size_t lowest = 0;
  double deepest = kInf;
  for (size_t i = 0; i < gs.size(); ++i) {
    // A local minimum over +-10 mm.
    bool minimum = true;
    for (size_t j = i >= 5 ? i - 5 : 0; j < std::min(gs.size(), i + 6); ++j) minimum = minimum && gs[j] >= gs[i];
    if (minimum && i > 0 && i + 1 < gs.size() && gs[i] < deepest) deepest = gs[i], lowest = i;
  }
  if (!(deepest < kInf)) lowest = arg_extreme(gs, false);
  // The knee's profile is shallow: its lowest sample wanders with the scan's noise.
  // The vertex of a parabola fitted over 2 % of the stature either side does not.
  Knee knee{ys[lowest], cs[lowest]};
  if (const std::optional<double> v = parabola_vertex(ys, gs, lowest, 0.02 * cuts.stature(), true)) {
    knee.y = *v;
    size_t near = lowest;
    for (size_t i = 0; i < ys.size(); ++i)
      if (std::abs(ys[i] - knee.y) < std::abs(ys[near] - knee.y)) near = i;
    knee.centre = cs[near];
  }
  return knee;
}

void measure_leg(const BodyCuts& cuts, MeasurementSheet& sheet, double crotch_y,
                 const PerSide<std::optional<Knee>>& knees, Side side) {
  const std::string sd = side_name(side), other_sd = side_name(opposite(side));
  const double stature = cuts.stature();
  // Thigh: the largest cut from kThighBelowCrotch of the stature below the crotch
  // (the tailor's "an inch below the crotch") down to 5 %.
  double thigh_y = crotch_y - 0.02 * stature;
  const Eigen::Vector3d thigh_c = extreme_cut(cuts, crotch_y, side, crotch_y - 0.05 * stature,
                                              crotch_y - kThighBelowCrotch * stature, true, &thigh_y, true);
  const std::optional<Girth> thigh_bridged =
      leg_loop(cuts, cuts.at(thigh_y), side) ? std::nullopt : bridged_leg(cuts, crotch_y, thigh_y, side);
  sheet.girth("thigh_girth_" + sd, "Thigh girth (" + sd + ")", "5.3.20",
              thigh_bridged ? StatusOr<Girth>(*thigh_bridged) : cuts.level_girth(thigh_y, thigh_c), {"crotch"},
              "horizontal, the largest from 1.5 % of the height below the crotch down");
  const std::optional<Knee>& knee = knees[side];
  if (!knee) {
    sheet.skip("knee_girth_" + sd, "no " + sd + " leg at knee height");
    return;
  }
  double calf_y = cuts.level(0.2);
  const Eigen::Vector3d calf_c = extreme_cut(cuts, crotch_y, side, cuts.level(0.10), knee->y, true, &calf_y);
  {
    const Ring* l = leg_loop(cuts, cuts.at(knee->y), side);
    sheet.landmark("knee_" + sd, {knee->centre.x(), knee->y, l ? l->z_max : knee->centre.z()});
  }
  // The knee height and the mid-thigh read the knees' mean level where they are
  // level (knee_reading_level).
  const std::optional<Knee>& other = knees[opposite(side)];
  const double reading_y = knee_reading_level(knee->y, other ? std::optional<double>(other->y) : std::nullopt);
  const bool level_knees = other && std::abs(other->y - knee->y) <= kLevelKneesMm;
  {
    const Eigen::Vector3d p = sheet.position("knee_" + sd);
    std::vector<std::string> knee_landmarks = {"knee_" + sd};
    if (level_knees) knee_landmarks.push_back("knee_" + other_sd);
    sheet.height("knee_height_" + sd, "Knee height (" + sd + ")", "", std::move(knee_landmarks),
                 {p.x(), reading_y, p.z()},
                 level_knees ? "the knees' mean level above the floor (standing, they lie within 10 mm)"
                             : "knee level above the floor");
  }
  sheet.girth("knee_girth_" + sd, "Knee girth (" + sd + ")", "5.3.22", cuts.level_girth(knee->y, knee->centre),
              {"knee_" + sd},
              "horizontal, the narrowest cut of the leg between calf and thigh (18-36 % of the height)");
  // Mid-thigh: halfway between the crotch and the knee's reading level.
  const double mid_y = 0.5 * (crotch_y + reading_y);
  const Ring* mid_leg = leg_loop(cuts, cuts.at(mid_y), side);
  std::vector<std::string> mid_landmarks = {"crotch", "knee_" + sd};
  if (level_knees) mid_landmarks.push_back("knee_" + other_sd);
  sheet.girth("mid_thigh_girth_" + sd, "Mid-thigh girth (" + sd + ")", "5.3.21",
              mid_leg ? cuts.level_girth(mid_y, mid_leg->centroid) : StatusOr<Girth>(not_found("no leg at mid-thigh")),
              mid_landmarks,
              level_knees ? "horizontal, halfway between crotch and the knees' mean level"
                          : "horizontal, halfway between crotch and kneecap");
  sheet.girth("calf_girth_" + sd, "Calf girth (" + sd + ")", "5.3.24", cuts.level_girth(calf_y, calf_c), {"knee_" + sd},
              "horizontal, the largest between ankle and knee");
  double ankle_y = cuts.level(0.06);
  const Eigen::Vector3d ankle_c = extreme_cut(cuts, crotch_y, side, cuts.level(0.04), calf_y, false, &ankle_y);
  sheet.girth("min_leg_girth_" + sd, "Minimum leg girth (" + sd + ")", "5.3.25", cuts.level_girth(ankle_y, ankle_c), {},
              "horizontal, the smallest between ankle and calf");
}

void read_stance(const BodyCuts& cuts, BodyPosture* posture) {
  // Each leg is the longest loop wholly on its side of the midline (a scrap the
  // surface left by a foot is not it), read at the first level from kAnkleLevel up
  // where both are.
  const double mid_x = cuts.midline_x();
  for (double f = kAnkleLevel; f <= kAnkleLevel + 0.03 + 1e-9; f += 0.01) {
    const Ring* legs[2] = {nullptr, nullptr};
    for (const Ring& x : cuts.at(cuts.level(f))) {
      if (x.spans_x(mid_x)) continue;
      const Ring*& l = legs[x.centroid.x() > mid_x ? 0 : 1];
      if (!l || x.girth > l->girth) l = &x;
    }
    if (legs[0] && legs[1]) {
      posture->ankle_distance_mm = (legs[0]->centroid - legs[1]->centroid).norm();
      return;
    }
  }
}

double knee_reading_level(double own_y, std::optional<double> other_y) {
  return other_y && std::abs(*other_y - own_y) <= kLevelKneesMm ? 0.5 * (own_y + *other_y) : own_y;
}

std::optional<Girth> bridged_part(const Ring& ring, double mid_x, Side side) {
  if (ring.confidence.size() != ring.points.size() || ring.crossing_confidence(mid_x) >= kMeasuredConfidence)
    return std::nullopt;
  return side_tape(ring, mid_x, side, true);
}

}  // namespace bodyscan::rules
