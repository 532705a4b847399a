#include "recon/measure/rules/trunk.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "recon/measure/profile.hpp"

namespace bodyscan::rules {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// A join (the legs' at the crotch, an arm's with the flank) counts where it has
// grown this long front to back, a fraction of the stature (widened): a smooth
// surface rounds the corner where two parts meet, and closes their gap a few mm
// early in a narrow saddle; a true crotch's floor is long where the legs first meet.
constexpr double kJoinDepth = 0.015;
// An arm against the flank touches it over at most this fraction of the stature
// below the armpit (find_arm_join).
constexpr double kContactOfStature = 0.04;
// Above a filled bridge, measured skin begins where the midline's crossing is
// measured over at least half of this height (mm) around the level (above_bridge).
constexpr double kBridgeWindowMm = 3;
// The waist is the centroid of the trunk's girth profile where it dips below its
// narrowest + this (mm): minimum_centroid.
constexpr double kWaistDepthMm = 6;
// A fold under the bust shallower than this behind its chord (mm) is flat at the
// bottom, and its level is a parabola's vertex; a deeper one is a crease.
constexpr double kShallowFoldMm = 10;
// A crease's level is the centroid of its bottom this deep (mm).
constexpr double kCreaseDepthMm = 2;
// Over a breast, the bust girth is the fullest within this fraction of the stature
// of the bust points' level.
constexpr double kBustReachOfStature = 0.012;
// A fold under the chest this deep (mm) or less is a man's, this deep or more a
// breast's crease; the bust girth's reach grows between them (breast_reach).
constexpr double kChestFoldMm = 6;
constexpr double kBreastFoldMm = 14;
// The waist's window stops under the under-bust only below a fold whose
// breast_reach is at least this (10 mm deep).
constexpr double kBreastBoundReach = 0.5;
// The bust's level ignores a bump in the front's profile this many 2 mm samples
// tall or less (despiked): a stray stripe's skin on a flat chest's midline.
constexpr size_t kBustBumpSamples = 2;
// A flat chest's top: where the front falls this far (mm) below its foremost on
// both sides, over more than 2 % of the stature.
constexpr double kBustTopDropMm = 1.5;
// A bust point is the centroid of its side's front within this (mm) of the foremost.
constexpr double kBustBandMm = 4;
// The front under the bust is the mean of this many columns either side of each
// bust point's X, this fraction of the stature apart.
constexpr int kUnderBustColumns = 3;
constexpr double kUnderBustStep = 0.0025;
// The hip's level: the fit's weights reach zero this far either side of its vertex,
// as a fraction of the stature.
constexpr double kHipHalf = 0.04;

// Up from where two parts join at height y: where the joined loop crosses the
// vertical plane X = x on invented surface only, front and back (hole filling's
// bridge across a gap no camera sees into), the first level above which the
// crossing is measured skin: where the crossing's confidence (front or back, the
// higher), sampled every quarter millimetre and averaged over kBridgeWindowMm
// around the level, reaches kMeasuredConfidence (interpolated), within `reach`.
// Else y: the join is measured, or the bridge reaches farther than that (wholly
// unseen). Where the bridge meets the skin, the crossing runs in and out of the
// filled patch, and small islands of measured surface lie just below the skin: over
// the window an island counts for its share, and a sharp edge of skin is read
// where it is.
double above_bridge(const BodyCuts& cuts, double y, double x, double reach) {
  const auto confidence = [&](double yy) -> double {
    const Ring* m = cuts.midline_loop(yy);
    return m ? m->crossing_confidence(x) : 1.0;
  };
  if (confidence(y + 0.5) >= kMeasuredConfidence) return y;
  constexpr double kStep = 0.25;
  const auto half = static_cast<size_t>(std::lround(kBridgeWindowMm / 2 / kStep));
  // From y + 0.5 up (the join's own level may lie just under the joined loop);
  // below it the window sees what y + 0.5 has, invented surface.
  const double y0 = y + 0.5;
  cuts.prefetch(y0, y0 + reach + kBridgeWindowMm, kStep);
  std::vector<double> c(half, confidence(y0));
  for (double yy = y0; yy <= y0 + reach + kBridgeWindowMm / 2; yy += kStep) c.push_back(confidence(yy));
  double sum = 0, prev = 0;
  for (size_t i = 0; i < 2 * half && i < c.size(); ++i) sum += c[i];
  for (size_t i = half; i + half < c.size(); ++i) {
    sum += c[i + half];
    const double mean = sum / static_cast<double>(2 * half + 1);
    if (mean >= kMeasuredConfidence) {
      const double at = static_cast<double>(i - half) - 1 + (kMeasuredConfidence - prev) / (mean - prev);
      return y0 + std::max(0.0, at) * kStep;
    }
    prev = mean;
    sum -= c[i - half];
  }
  return y;
}

// Up from a join at y (legs, or arm and flank), the level where the midline loop's
// crossing of the plane X = x has grown `span` long front to back (interpolated
// between 1 mm cuts), within `reach`; y if it never does.
double widened(const BodyCuts& cuts, double y, double x, double span, double reach) {
  const auto length = [&](double yy) {
    double f = 0, b = 0;
    const Ring* m = cuts.midline_loop(yy);
    return m && m->crossing_z(x, &f, &b) ? std::abs(f - b) : 0.0;
  };
  cuts.prefetch(y, y + reach, 1);
  double at = y + 0.5, prev = length(at);
  if (prev >= span) return y;
  for (double yy = at + 1; yy <= y + reach; yy += 1) {
    const double l = length(yy);
    if (l >= span) return at + (span - prev) / (l - prev) * (yy - at);
    at = yy, prev = l;
  }
  return y;
}

// f of the midline loop every 2 mm from y0 to y1, where there is one: (levels, values).
std::pair<std::vector<double>, std::vector<double>> midline_profile(const BodyCuts& cuts, double y0, double y1,
                                                                    const std::function<double(const Ring&)>& f) {
  std::pair<std::vector<double>, std::vector<double>> out;
  cuts.prefetch(y0, y1, 2);
  for (double y = y0; y <= y1; y += 2)
    if (const Ring* m = cuts.midline_loop(y)) out.first.push_back(y), out.second.push_back(f(*m));
  return out;
}

// The level where f of the midline loop is extreme between y0 and y1 (`fallback`
// where there is no loop): the middle of the run within `tol` of the extreme sample
// (after despiking bumps up to `bump` samples tall, if `bump` > 0). With `refine` >
// 0, the vertex of a parabola fitted over `refine` either side of it, fitted a
// second time round the sample nearest the first vertex: a flat extreme's middle
// moves with the skin's noise, the vertex much less. With `settled`, first the
// vertex of a parabola whose weights fall to zero `refine` either side of the
// vertex itself (settled_vertex).
double extreme_level(const BodyCuts& cuts, double y0, double y1, const std::function<double(const Ring&)>& f,
                     bool largest, double tol, double fallback, double refine = 0, bool settled = false,
                     size_t bump = 0) {
  auto [ys, vs] = midline_profile(cuts, y0, y1, f);
  if (ys.empty()) return fallback;
  if (bump > 0) vs = despiked(vs, bump, tol);
  size_t k = settle(vs, arg_extreme(vs, largest), tol);
  if (settled && refine > 0)
    if (const std::optional<double> v = settled_vertex(ys, vs, k, refine, !largest)) return *v;
  double level = ys[k];
  for (int pass = 0; refine > 0 && pass < 2; ++pass) {
    const std::optional<double> v = parabola_vertex(ys, vs, k, refine, !largest);
    if (!v) break;
    level = *v;
    for (size_t i = 0; i < ys.size(); ++i)
      if (std::abs(ys[i] - *v) < std::abs(ys[k] - *v)) k = i;
  }
  return level;
}

// The bust's level: the chest's most forward point, 1-12 % of the stature below
// the lower armpit. The front's profile is despiked first (a stray bump on a flat
// chest is no bust). Where the front falls kBustTopDropMm below its foremost on
// both sides over more than 2 % of the stature (a flat chest, whose foremost
// sample and a narrow fit both follow ripples of a few tenths of a millimetre), the
// level is the vertex of a parabola over that whole top; else the vertex of one
// over 1 % of the stature either side of the foremost (a breast's apex).
double bust_level(const BodyCuts& cuts, double lower_armpit_y) {
  const double stature = cuts.stature();
  const double y0 = lower_armpit_y - 0.12 * stature, y1 = lower_armpit_y - 0.01 * stature;
  const auto front = [](const Ring& m) { return m.z_max; };
  auto [ys, vs] = midline_profile(cuts, y0, y1, front);
  std::optional<double> level;
  if (!ys.empty()) level = flat_top_vertex(ys, despiked(vs, kBustBumpSamples, 0.5), kBustTopDropMm, 0.02 * stature);
  return level ? *level
               : extreme_level(cuts, y0, y1, front, true, 0.5, lower_armpit_y - 0.06 * stature, 0.01 * stature, false,
                               kBustBumpSamples);
}

// The bust point on `side` at the bust's level: across a breast the front is flat
// at the apex's level and its foremost point jumps from side to side with the
// skin's noise, so the point is the centroid of the front within kBustBandMm of
// the foremost, weighted by how far inside that band it lies, on the front where it
// crosses that X.
Eigen::Vector3d bust_point(const BodyCuts& cuts, double bust_y, Side side) {
  const double mid_x = cuts.midline_x(), stature = cuts.stature(), s = sign(side);
  const Ring* m = cuts.midline_loop(bust_y);
  Eigen::Vector3d p(mid_x + s * 0.05 * stature, bust_y, cuts.midline_z());
  double z = -kInf;
  if (m)
    for (const Eigen::Vector3d& q : m->points)
      if (s * (q.x() - mid_x) > 0.01 * stature && q.z() > z) z = q.z(), p = q;
  double sw = 0, sx = 0, f = 0, b = 0;
  if (m)
    for (const Eigen::Vector3d& q : m->points)
      if (const double w = q.z() - (z - kBustBandMm); s * (q.x() - mid_x) > 0.01 * stature && w > 0)
        sw += w, sx += w * q.x();
  if (sw > 0 && m->crossing_z(sx / sw, &f, &b)) p = {sx / sw, bust_y, f};
  return p;
}

// The front under the bust, top down from bust_y over 10 % of the stature, as (y,
// front z): the mean over kUnderBustColumns columns either side of each bust
// point's X (one column follows the skin's noise); a level where a column misses
// the front is left out.
std::vector<Eigen::Vector2d> front_under_bust(const BodyCuts& cuts, const MeasurementSheet& sheet, double bust_y) {
  const double stature = cuts.stature();
  const double xb = 0.5 * (sheet.position("bust_point_left").x() + sheet.position("bust_point_right").x());
  const double xs = 0.5 * (sheet.position("bust_point_left").x() - sheet.position("bust_point_right").x());
  std::vector<Eigen::Vector2d> front;
  cuts.prefetch(bust_y, bust_y - 0.1 * stature, -2);
  for (double y = bust_y; y >= bust_y - 0.1 * stature; y -= 2) {
    const Ring* m = cuts.midline_loop(y);
    double f = 0, b = 0, f2 = 0, b2 = 0, sum = 0;
    int n = 0;
    for (int j = -kUnderBustColumns; m && j <= kUnderBustColumns; ++j) {
      const double o = j * kUnderBustStep * stature;
      if (!m->crossing_z(xb + xs + o, &f, &b) || !m->crossing_z(xb - xs - o, &f2, &b2)) break;
      sum += f + f2, n += 2;
    }
    if (n == 2 * (2 * kUnderBustColumns + 1)) front.emplace_back(y, sum / n);
  }
  return front;
}

// The fold's level on a stretch of the front under the bust (at least 3 samples),
// and its depth behind the stretch's chord (<= 0). A shallow fold (a man's) is
// flat at the bottom, and its deepest sample is the skin noise's: there the vertex
// of a parabola over 2 % of the stature either side stands. A deep fold is a
// crease, steep above and gentle below, where that vertex would slide down the
// ribs: there the centroid of the crease's bottom kCreaseDepthMm deep.
std::pair<double, double> fold_level(const std::vector<Eigen::Vector2d>& front, double stature) {
  const Notch notch = deepest_behind_chord(front, 0.02 * stature);
  double y = front[notch.k].x();
  if (notch.depth > -kShallowFoldMm && notch.vertex_y) y = *notch.vertex_y;
  if (notch.depth <= -kShallowFoldMm) y = minimum_centroid(notch.ys, notch.depths, notch.k, kCreaseDepthMm);
  return {y, notch.depth};
}

// Waist: the narrowest trunk between hip and under-bust. Only a breast's crease
// (`crease_y`: a fold at least halfway from a man's to a breast's,
// kBreastBoundReach) bounds the window: a man's fold is a shelf a few mm deep, and
// a belly's dome has no fold. Otherwise the window runs to 70 % of the stature.
// The level is the centroid of the girth profile's dip kWaistDepthMm deep: a flat
// waist's narrowest cut moves with the skin's noise.
double waist_level(const BodyCuts& cuts, double hip_y, std::optional<double> crease_y) {
  const double stature = cuts.stature();
  double lo = std::max(hip_y + 0.04 * stature, cuts.level(0.55)),
         hi = crease_y ? std::min(*crease_y - 0.02 * stature, cuts.level(0.70)) : cuts.level(0.70);
  if (lo >= hi && crease_y) lo = hip_y + 0.04 * stature, hi = *crease_y - 0.02 * stature;
  const auto [ys, vs] = midline_profile(cuts, lo, hi, [](const Ring& m) { return m.girth; });
  return ys.empty() ? 0.5 * (lo + hi) : minimum_centroid(ys, vs, arg_extreme(vs, false), kWaistDepthMm);
}

// An arm that lies against the flank joins it where they touch, below the
// armpit, and parts from it again above the contact: the gap under the armpit is
// the last run of cuts, however short, that begins within kContactOfStature above
// the one before. `joined` is the first cut (every `step` mm) above a run whose
// last cut is `last`; `apart` says whether the arm is its own loop at a level. The
// last run's top (bisected), if the arm parts again; else none.
std::optional<double> gap_top_above_contact(const BodyCuts& cuts, const std::function<bool(double)>& apart,
                                            double joined, double last, double step) {
  const double reach = kContactOfStature * cuts.stature(), top = cuts.level(0.95);
  bool parted_again = false;
  for (double u = joined + step; u <= joined + reach && u < top; u += step) {
    if (!apart(u)) continue;
    parted_again = true;
    for (last = u; last + step < top && apart(last + step);) last += step;
    joined = u = last + step;
  }
  if (!parted_again) return std::nullopt;
  return bisect(joined, last, apart);
}

// The level between lo and hi where the midline loop's tape is longest, every 2 mm
// and then every 0.5 mm round the longest; only where both arms are clear of the
// trunk: an arm that lies against the flank joins it (or, posed by skinning,
// passes through it) below the armpit, and the tape there would go round the arm.
std::optional<double> fullest_level(const BodyCuts& cuts, double lo, double hi) {
  const auto arms_clear = [&](double y) { return cuts.arm_clear(y, Side::kLeft) && cuts.arm_clear(y, Side::kRight); };
  std::optional<double> level;
  double best = -kInf;
  cuts.prefetch(lo, hi, 2);
  for (double y = lo; y <= hi; y += 2)
    if (const Ring* m = cuts.midline_loop(y); m && m->girth > best && arms_clear(y)) best = m->girth, level = y;
  if (!level) return std::nullopt;
  const double coarse = *level;
  for (double y = coarse - 1.5; y <= coarse + 1.5; y += 0.5)
    if (const Ring* m = y >= lo && y <= hi ? cuts.midline_loop(y) : nullptr; m && m->girth > best && arms_clear(y))
      best = m->girth, level = y;
  return level;
}

}  // namespace

StatusOr<double> find_crotch(const BodyCuts& cuts, MeasurementSheet& sheet) {
  const double mid_x = cuts.midline_x(), stature = cuts.stature(), span = kJoinDepth * stature;
  auto merged = [&](double y) { return cuts.midline_loop(y) != nullptr; };
  // The trunk's own loop: one spanning the midline at least `span` long front to
  // back where it crosses it.
  auto trunk = [&](double y) {
    double f = 0, b = 0;
    const Ring* m = cuts.midline_loop(y);
    return m != nullptr && m->crossing_z(mid_x, &f, &b) && f - b >= span;
  };
  // Down from the trunk, the first level where no loop spans the midline: the legs
  // apart. Walked down rather than up, since legs held close can touch lower down
  // (knees, calves) and join there again; the crotch is where the trunk's loop
  // parts, not where the legs first meet.
  const double step = 5;
  const double top = cuts.level(0.55), bottom = cuts.level(0.25);
  cuts.prefetch(top, bottom, -step);
  double above = top, above_trunk = top;
  double crotch_y = -1, trunk_end = -1;
  for (double y = top - step; y >= bottom; y -= step) {
    if (trunk_end < 0 && !trunk(y)) trunk_end = bisect(y, above_trunk, trunk);
    if (trunk_end < 0) above_trunk = y;
    if (!merged(y)) {
      crotch_y = bisect(y, above, merged);
      break;
    }
    above = y;
  }
  if (crotch_y < 0 && trunk_end < 0)
    return not_found(
        "measure: the legs are not apart below the trunk down to a quarter of the height; stand with "
        "feet apart");
  if (crotch_y < 0) crotch_y = bottom;  // joined all the way down
  // Thighs that touch (heavy or muscular ones, the feet close) join along their
  // contact, a strip narrower than a crotch's floor: where the narrow join runs
  // down more than `span` (farther than the saddle a smooth surface leaves under a
  // crotch), the crotch is its top.
  if (trunk_end - crotch_y > span) crotch_y = trunk_end;
  // Where the thighs nearly touch no camera sees between them, and the surface
  // bridges the gap below the real crotch; the real crotch's front and back are
  // seen. Up from the join, the first level whose midline crossings are measured
  // skin, within 5 % of the stature.
  crotch_y = above_bridge(cuts, crotch_y, mid_x, 0.05 * stature);
  // A smooth surface rounds the corner where measured thighs meet, closing their
  // gap a few mm below the crotch in a narrow saddle: the crotch is where the join
  // has grown kJoinDepth of the stature long.
  crotch_y = widened(cuts, crotch_y, mid_x, span, 0.02 * stature);
  // Front to back, the middle of the join's first kJoinDepth from its back: the
  // join's front runs into the notch between the thighs, and jumps out of it as the
  // notch closes over a fraction of a millimetre of height.
  double f = cuts.midline_z(), b = cuts.midline_z();
  if (const Ring* m = cuts.midline_loop(crotch_y + 0.5)) m->crossing_z(mid_x, &f, &b);
  sheet.landmark("crotch", {mid_x, crotch_y, b + 0.5 * std::min(f - b, span)});
  return crotch_y;
}

StatusOr<ArmJoin> find_arm_join(const BodyCuts& cuts, MeasurementSheet& sheet, double crotch_y, Side side) {
  const double mid_x = cuts.midline_x(), stature = cuts.stature();
  auto arm = [&](double y) { return cuts.arm_loop(cuts.at(y), side) != nullptr; };
  // Upwards from just above the crotch, the first run of cuts with the arm apart
  // from the body that is at least 4 % of the stature long (a scrap that comes and
  // goes is not).
  const double step = 5;
  double y = crotch_y + 0.03 * stature, first = y, last = y;
  cuts.prefetch(y, cuts.level(0.8), step);
  for (;; y += step) {
    while (y < cuts.level(0.9) && !arm(y)) y += step;
    if (y >= cuts.level(0.9))
      return not_found("measure: no " + side_name(side) +
                       " arm apart from the body; hold the arms away from the sides");
    first = last = y;
    for (y += step; y < cuts.level(0.95) && arm(y); y += step) last = y;
    if (last - first >= 0.04 * stature) break;
  }
  ArmJoin join;
  join.followed_from_y = bisect(y, last, arm);
  join.apart_y = gap_top_above_contact(cuts, arm, y, last, step).value_or(join.followed_from_y);
  // The armpit: halfway across the last gap between arm and trunk.
  const std::vector<Ring>& cut = cuts.at(join.apart_y - 0.5);
  const Ring* a = cuts.arm_loop(cut, side);
  const Ring* t = midline_ring(cut, mid_x);
  Eigen::Vector3d p(mid_x + sign(side) * 0.1 * stature, join.apart_y, cuts.midline_z());
  if (a && t) {
    double best = kInf;
    for (const Eigen::Vector3d& u : a->points)
      for (const Eigen::Vector3d& v : t->points)
        if ((u - v).squaredNorm() < best) best = (u - v).squaredNorm(), p = 0.5 * (u + v);
  }
  // As at the crotch: no camera sees the top of the armpit, and hole filling can
  // bridge the gap between arm and flank below it. Where the joined loop crosses
  // the gap's plane on invented surface only, front and back, the armpit is the
  // first level above where one of those crossings is measured skin, if that is
  // within 1 % of the stature. Farther up the top is wholly unseen, and the armpit
  // stays at the join.
  join.armpit_y = above_bridge(cuts, join.apart_y, p.x(), 0.01 * stature);
  // The chest is cut under the armpit's vault: a scan's join narrows to a saddle a
  // few mm below the true armpit, as far as its noise takes it, and the vault (where
  // the join has grown kJoinDepth long) does not move with that. The armpit itself
  // stays at the join: the neck and shoulder searches start from it.
  join.vault_y = widened(cuts, join.armpit_y, p.x(), kJoinDepth * stature, 0.02 * stature);
  p.y() = join.armpit_y;
  sheet.landmark("armpit_" + side_name(side), p);
  return join;
}

TrunkLevels find_trunk_levels(const BodyCuts& cuts, MeasurementSheet& sheet, double crotch_y,
                              const PerSide<ArmJoin>& arms) {
  const double mid_x = cuts.midline_x(), mid_z = cuts.midline_z(), stature = cuts.stature();
  const double lower_armpit_y = std::min(arms.left.armpit_y, arms.right.armpit_y);
  TrunkLevels out;
  out.bust_y = bust_level(cuts, lower_armpit_y);
  for (Side side : kBothSides) sheet.landmark("bust_point_" + side_name(side), bust_point(cuts, out.bust_y, side));

  // Under-bust: below the bust points, the front's deepest point behind the chord.
  const std::vector<Eigen::Vector2d> front = front_under_bust(cuts, sheet, out.bust_y);
  out.underbust_y = out.bust_y - 0.05 * stature;
  if (front.size() >= 3) {
    const auto [y, depth] = fold_level(front, stature);
    out.underbust_y = y;
    out.underbust_fold = depth < 0;
    out.breast = breast_reach(-depth);
  }
  const bool breast_crease = out.underbust_fold && out.breast >= kBreastBoundReach;

  // Hip: the buttocks' greatest backward projection. The back is flat over its
  // backmost on a heavy body, so the level is the vertex of a parabola whose weights
  // fall to zero kHipHalf of the stature either side of itself.
  out.hip_y = extreme_level(
      cuts, crotch_y + 0.01 * stature, crotch_y + 0.16 * stature, [](const Ring& m) { return m.z_min; }, false, 0.5,
      crotch_y + 0.08 * stature, kHipHalf * stature, true);
  // The hip's back point is on the tape at the centre back: the tape spans the
  // cleft between the buttocks at their backmost, wherever on either side that is.
  Eigen::Vector3d hip_point(mid_x, out.hip_y, mid_z);
  if (const Ring* m = cuts.midline_loop(out.hip_y)) hip_point.z() = m->z_min;
  sheet.landmark("hip_back_point", hip_point);

  out.waist_y = waist_level(cuts, out.hip_y, breast_crease ? std::optional<double>(out.underbust_y) : std::nullopt);
  double f = mid_z, b = mid_z;
  if (const Ring* m = cuts.midline_loop(out.waist_y)) m->crossing_z(mid_x, &f, &b);
  sheet.landmark("waist_back_point", {mid_x, out.waist_y, b});
  sheet.landmark("waist_front_point", {mid_x, out.waist_y, f});

  // Below a man's shallow fold the belly's hollow over the waist can lie deeper
  // behind the chord than the fold itself, and whether it falls inside a window of
  // fixed length depends on where the bust's level is: his under-bust is sought
  // between the bust and the waist.
  if (!breast_crease) {
    std::vector<Eigen::Vector2d> above_waist;
    for (const Eigen::Vector2d& q : front)
      if (q.x() >= out.waist_y) above_waist.push_back(q);
    if (above_waist.size() >= 3 && above_waist.size() < front.size())
      out.underbust_y = fold_level(above_waist, stature).first;
  }
  sheet.landmark("underbust_front_point", {mid_x, out.underbust_y, cuts.front_z(out.underbust_y)});

  // The bust girth's level. A tape is read at its fullest across the prominence
  // (EN 13402-1: "maximum horizontal girth ... across the bust prominence"): over a
  // breast the tape grows steeply through the apex's level to its fullest a few mm
  // above, so the largest girth within kBustReachOfStature of the apex's level,
  // below the armpits, every 2 mm and then every 0.5 mm round the largest. A man's
  // chest rises into the armpits with no such fullest level, and the crease
  // beneath tells them apart: a man's is read at the apex's level, and between the
  // two the reach grows with the crease's depth (breast_reach).
  out.bust_girth_y = out.bust_y;
  if (out.breast > 0) {
    const double reach = out.breast * kBustReachOfStature * stature;
    out.bust_girth_y =
        fullest_level(cuts, out.bust_y - reach,
                      std::max(out.bust_y, std::min(out.bust_y + reach, lower_armpit_y - 0.01 * stature)))
            .value_or(out.bust_y);
  }

  return out;
}

void measure_trunk(const BodyCuts& cuts, MeasurementSheet& sheet, double crotch_y, const PerSide<ArmJoin>& arms,
                   const TrunkLevels& levels) {
  const double stature = cuts.stature();
  auto tape = [&](double y) { return cuts.level_girth(y, cuts.on_midline(y)); };
  // Under the two armpits' vaults: 0.5 % of the stature under their mean level.
  // Each vault is read where a scan's measured skin begins, a few mm off on either
  // side independently, and there the tape grows about 1 mm per mm of height: the
  // mean moves half as far as either, and while the vaults differ by less than 1 %
  // of the stature the tape is under both. And below where either arm's own loop
  // ends: above it, where the armpit's top was a filled bridge, the cut's loop
  // holds that arm too.
  const double chest_y = std::min(0.5 * (arms.left.vault_y + arms.right.vault_y) - 0.005 * stature,
                                  std::min(arms.left.apart_y, arms.right.apart_y) - 0.5);
  sheet.girth("chest_girth", "Chest girth", "5.3.6", tape(chest_y), {"armpit_left", "armpit_right"},
              "horizontal, just under the armpits' vaults (where the join of arm and flank is 1.5 % of the height "
              "deep)");
  sheet.girth("bust_girth", "Bust girth", "5.3.4", tape(levels.bust_girth_y), {"bust_point_left", "bust_point_right"},
              levels.breast > 0
                  ? "horizontal, the fullest within 1.2 % of the height of the bust points' level (across the "
                    "breasts' prominence; less where the crease beneath is under 14 mm deep)"
                  : "horizontal, at the level of the chest's most forward point (no breast's crease beneath)");
  sheet.girth("underbust_girth", "Under-bust girth", "5.3.8", tape(levels.underbust_y), {"underbust_front_point"},
              "horizontal, where the front turns in below the bust");
  sheet.girth("waist_girth", "Waist girth", "5.3.10", tape(levels.waist_y), {"waist_back_point", "waist_front_point"},
              "horizontal, at the narrowest torso between hip level and under-bust (55-70 % of the height)");
  sheet.girth("hip_girth", "Hip girth", "5.3.13", tape(levels.hip_y), {"hip_back_point"},
              "horizontal, at the level of the buttocks' greatest backward projection");
  {
    double best = -kInf, fullest_y = levels.hip_y;
    cuts.prefetch(crotch_y + 0.01 * stature, levels.waist_y, 2);
    for (double y = crotch_y + 0.01 * stature; y <= levels.waist_y; y += 2)
      if (const Ring* m = cuts.midline_loop(y); m && m->girth > best) best = m->girth, fullest_y = y;
    sheet.girth("max_hip_girth", "Maximum hip girth", "5.3.14", tape(fullest_y), {"crotch", "waist_back_point"},
                "horizontal, the largest between crotch and waist");
  }
  sheet.height("waist_height", "Waist height", "5.1.10", {"waist_back_point"}, sheet.position("waist_back_point"),
               "waist level above the floor");
  sheet.height("hip_height", "Hip height", "", {"hip_back_point"}, sheet.position("hip_back_point"),
               "hip level above the floor");
}

double breast_reach(double fold_depth_mm) {
  return std::clamp((fold_depth_mm - kChestFoldMm) / (kBreastFoldMm - kChestFoldMm), 0.0, 1.0);
}

}  // namespace bodyscan::rules
