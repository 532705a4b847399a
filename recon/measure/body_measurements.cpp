#include "recon/measure/body_measurements.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <functional>
#include <future>
#include <limits>
#include <optional>
#include <unordered_map>

#include <tbb/parallel_for.h>

#include "recon/measure/body_frame.hpp"
#include "recon/measure/body_slicer.hpp"
#include "recon/measure/girth.hpp"
#include "recon/measure/surface_path.hpp"

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
  static const char* const kTorso[] = {"chest_girth", "bust_girth",     "underbust_girth",
                                       "waist_girth", "hip_girth", "max_hip_girth"};
  if (m.kind == "girth") return std::find(std::begin(kTorso), std::end(kTorso), m.name) != std::end(kTorso) ? 9 : 4;
  return m.kind == "height" ? 4 : 5;
}

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// How far below a flat extreme a point still counts as on it, mm.
constexpr double kFlatBand = 3;
// The same for the neck's side at its base, flat front to back: over 3 mm the
// parabola's vertex moved 3.7 mm under +-0.5 mm of skin noise.
constexpr double kNeckSideBand = 5;
// The neck's base (the side neck points) is where the front outline has flared to
// this many times the radius of the neck's narrowest horizontal tape
// (find_side_neck).
constexpr double kNeckBaseWidth = 1.3;
// The same for the top of the shoulder, which is broad front to back: a parabola over
// 3 mm of it is nearly flat, and its vertex moved 7-8 mm under +-0.5 mm of noise.
constexpr double kRidgeBand = 10;
// A join (the legs' at the crotch, an arm's with the flank) counts where it has
// grown this long front to back (a fraction of the height; Finder::widened).
constexpr double kJoinDepth = 0.015;
// Above a filled bridge, measured skin begins where the midline's crossing is
// measured over at least half of this height (mm) around the level
// (Finder::above_bridge).
constexpr double kBridgeWindowMm = 3;
// The thigh's tape is taken this far (a fraction of the height) below the crotch
// or lower (measure_leg).
constexpr double kThighBelowCrotch = 0.015;
// The middle of a flat minimum (the forearm's at the wrist, the neck's) is halfway
// between where the tape has grown by this much (mm) either side
// (flat_bottom_middle).
constexpr double kFlatRiseMm = 3;
// The waist is the centroid of the torso's girth profile where it dips below its
// narrowest + this (mm): minimum_centroid.
constexpr double kWaistDepthMm = 6;
// A fold under the bust shallower than this behind its chord (mm) is flat at the
// bottom, and is refined as the front neck point; a deeper one is a crease.
constexpr double kShallowFoldMm = 10;
// Over a breast, the bust girth is the fullest within this fraction of the stature
// of the bust points' level (find_torso_levels).
constexpr double kBustReachOfHeight = 0.012;
// A fold under the chest this deep (mm) or less is a man's, this deep or more a
// breast's crease; the bust girth's reach grows between them (breast_reach).
constexpr double kChestFoldMm = 6;
constexpr double kBreastFoldMm = 14;
// The bust's level ignores a bump in the front's profile this many 2 mm samples
// tall or less (despiked).
constexpr size_t kBustBumpSamples = 2;
// A flat chest's top: where the front falls this far (mm) below its foremost on
// both sides, over more than 2 % of the height.
constexpr double kBustTopDropMm = 1.5;
// A bust point is the centroid of its side's front within this (mm) of the foremost.
constexpr double kBustBandMm = 4;
// The front under the bust is the mean of this many columns either side of each
// bust point's X, this fraction of the stature apart (0.0025: 4-5 mm).
constexpr int kUnderBustColumns = 3;
constexpr double kUnderBustStep = 0.0025;
// The least bend (radians) between upper arm and forearm at which the elbow is
// where their axes meet (measure_arm).
constexpr double kMinElbowBend = 10 * M_PI / 180;
// The shoulder's corner: the fit's weights reach zero this far either side of its
// vertex, as a fraction of the stature (find_shoulder).
constexpr double kCornerHalf = 0.04;
// The wrist's level along the forearm: the fit's weights reach zero this far either
// side of its vertex, as a fraction of the stature (24 mm on male_average).
constexpr double kWristHalf = 0.014;
// The wrist is this fraction of the stature back toward the elbow from where the
// tape, cut by cut toward the hand, has grown kWristFlareMm (mm) over the forearm's
// narrowest cut (measure_arm).
constexpr double kWristBeforeFlare = 0.01;
constexpr double kWristFlareMm = 7;
// The hip's level: the fit's weights reach zero this far either side of its vertex,
// as a fraction of the stature (find_torso_levels).
constexpr double kHipHalf = 0.04;
// Knees whose levels lie within this (mm) of each other are level: the knee heights
// and the mid-thigh take their mean (knee_reading_level).
constexpr double kLevelKneesMm = 10;
// A second narrowing of the forearm's cuts nearer the hand, past a rise of more
// than this (mm) and within this of the narrowest, is the wrist (wrist_cut).
constexpr double kSecondNarrowMm = 2;
// A deeper fold is a crease: its level is the centroid of its bottom this deep (mm).
constexpr double kCreaseDepthMm = 2;
// The ankles' height, a fraction of the stature: the stance is read from the legs'
// centres there (BodyPosture::ankle_distance_mm).
constexpr double kAnkleLevel = 0.05;

// The loop that spans the midline X = xc (torso, neck, head), the longest if several.
const Ring* midline(const std::vector<Ring>& rings, double xc) {
  const Ring* best = nullptr;
  for (const Ring& r : rings)
    if (r.spans_x(xc) && (!best || r.girth > best->girth)) best = &r;
  return best;
}

// Loops wholly on side s (+1 left, -1 right) of the midline: `farthest` picks the
// arm (outermost), otherwise the leg (innermost).
const Ring* side_ring(const std::vector<Ring>& rings, double xc, int s, bool farthest, double min_girth = 30) {
  const Ring* best = nullptr;
  double best_d = 0;
  for (const Ring& r : rings) {
    if (r.spans_x(xc) || r.girth < min_girth) continue;
    const double d = s * (r.centroid.x() - xc);
    if (d <= 0) continue;
    if (!best || (farthest ? d > best_d : d < best_d)) best = &r, best_d = d;
  }
  return best;
}

// How many other loops of the cut (of a tape's girth at least min_girth) lie within
// `reach` of the part's centre: fingers parting from a hand. A stray fold of the
// reconstruction against the flank, far from the arm, is not counted.
size_t parts_near(const std::vector<Ring>& rings, const Ring& part, double reach, double min_girth = 30) {
  size_t n = 0;
  for (const Ring& r : rings)
    if (&r != &part && r.girth >= min_girth && (r.centroid - part.centroid).norm() < reach) ++n;
  return n;
}

// The middle of a flat extreme: of the points whose height along `dir` lies within
// `band` of the highest, the one nearest (along `across`) to the vertex of the
// parabola least-squares fitted to their heights, or to the middle of their span
// where the fit does not open downwards or its vertex falls outside. The highest
// point alone slides from end to end of a flat side (a neck's, the top of a
// shoulder) with the scan's noise; so, less, does the span's middle. With
// `between`, the point at that middle itself, interpolated between the nearest
// points either side of it along `across` (for points on one arch, such as a
// section's top): a mesh's section has a point every few mm (5-10 on the true
// bodies), and the nearest one jumps from one to the next.
Eigen::Vector3d middle_of_extreme(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& dir,
                                  const Eigen::Vector3d& across, double band, bool between = false) {
  double top = -kInf;
  for (const Eigen::Vector3d& p : pts) top = std::max(top, p.dot(dir));
  double lo = kInf, hi = -kInf;
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d atb = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : pts)
    if (p.dot(dir) >= top - band) {
      const double t = p.dot(across);
      lo = std::min(lo, t), hi = std::max(hi, t);
      const Eigen::Vector3d row(t * t, t, 1);
      ata += row * row.transpose(), atb += row * p.dot(dir);
    }
  double mid = 0.5 * (lo + hi);
  const Eigen::Vector3d c = ata.ldlt().solve(atb);
  if (c.x() < 0 && -c.y() / (2 * c.x()) > lo && -c.y() / (2 * c.x()) < hi) mid = -c.y() / (2 * c.x());
  Eigen::Vector3d best = pts.front();
  double best_d = kInf;
  const Eigen::Vector3d* below = nullptr;  // the nearest points either side of the middle
  const Eigen::Vector3d* above = nullptr;
  for (const Eigen::Vector3d& p : pts) {
    if (p.dot(dir) < top - band) continue;
    const double t = p.dot(across);
    if (std::abs(t - mid) < best_d) best_d = std::abs(t - mid), best = p;
    if (t <= mid && (!below || t > below->dot(across))) below = &p;
    if (t >= mid && (!above || t < above->dot(across))) above = &p;
  }
  if (between && below && above && above->dot(across) > below->dot(across)) {
    const double f = (mid - below->dot(across)) / (above->dot(across) - below->dot(across));
    return *below + f * (*above - *below);
  }
  return best;
}

// Where the ray from `origin` along `dir` last leaves a closed loop lying in a plane
// through `origin` that holds `dir` and `across`: the loop's outermost crossing of
// that line. On a limb's round side the middle of the flattest stretch slides round
// with a few tenths of a millimetre of skin noise (an elbow's outer point moved 5 mm
// round the arm, and the outer arm length 4 mm); the crossing moves only as far as
// the skin does. Empty when the ray never crosses the loop.
std::optional<Eigen::Vector3d> ray_exit(const std::vector<Eigen::Vector3d>& loop, const Eigen::Vector3d& origin,
                                        const Eigen::Vector3d& dir, const Eigen::Vector3d& across) {
  std::optional<Eigen::Vector3d> out;
  double far = 0;
  for (size_t i = 0, n = loop.size(); i < n; ++i) {
    const Eigen::Vector3d& a = loop[i];
    const Eigen::Vector3d& b = loop[(i + 1) % n];
    const double va = (a - origin).dot(across), vb = (b - origin).dot(across);
    if ((va < 0) == (vb < 0) || va == vb) continue;
    const double f = va / (va - vb);
    const Eigen::Vector3d q = a + f * (b - a);
    if (const double t = (q - origin).dot(dir); t > far) far = t, out = q;
  }
  return out;
}

// The centre of a closed loop's outline: its edges' midpoints weighted by their
// lengths (unlike the vertices' mean, indifferent to where the cut samples densely).
Eigen::Vector3d loop_centre(const std::vector<Eigen::Vector3d>& loop) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double len = 0;
  for (size_t i = 0, n = loop.size(); i < n; ++i) {
    const Eigen::Vector3d& a = loop[i];
    const Eigen::Vector3d& b = loop[(i + 1) % n];
    const double l = (b - a).norm();
    sum += 0.5 * l * (a + b), len += l;
  }
  return len > 0 ? (sum / len).eval() : (loop.empty() ? Eigen::Vector3d::Zero() : loop.front());
}

// Least-squares line through points: (centre, unit direction with y >= 0).
std::pair<Eigen::Vector3d, Eigen::Vector3d> fit_line(const std::vector<Eigen::Vector3d>& p, size_t b, size_t e,
                                                      double* residual = nullptr) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (size_t i = b; i < e; ++i) c += p[i];
  c /= static_cast<double>(e - b);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (size_t i = b; i < e; ++i) cov += (p[i] - c) * (p[i] - c).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  Eigen::Vector3d d = es.eigenvectors().col(2);
  if (d.y() < 0) d = -d;
  if (residual) *residual = es.eigenvalues()(0) + es.eigenvalues()(1);
  return {c, d};
}

// Whether a loop in the plane with normal n winds round p (the loop is the limb's
// own, not a neighbour's that the nearest-loop rule fell back to).
bool winds_round(const std::vector<Eigen::Vector3d>& loop, const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
  Eigen::Vector3d u, v;
  plane_basis(n, &u, &v);
  double turn = 0;
  for (size_t i = 0; i < loop.size(); ++i) {
    const Eigen::Vector3d a = loop[i] - p, b = loop[(i + 1) % loop.size()] - p;
    turn += std::atan2(a.dot(u) * b.dot(v) - a.dot(v) * b.dot(u), a.dot(u) * b.dot(u) + a.dot(v) * b.dot(v));
  }
  return std::abs(turn) > M_PI;
}

class Finder {
 public:
  Finder(const TriangleMesh& mesh, const BodyMeasureOptions& options, BodyMeasurements* out)
      : mesh_(mesh), opt_(options), out_(out) {}

  Status run() {
    if (mesh_.triangles.empty()) return invalid_argument("measure: the mesh has no triangles");
    double lo = kInf, hi = -kInf;
    for (const Vec3f& v : mesh_.vertices) {
      if (v.y() > hi) hi = v.y(), top_ = v.cast<double>();
      lo = std::min(lo, static_cast<double>(v.y()));
    }
    floor_ = opt_.floor_y.value_or(lo);
    out_->floor_y = floor_;
    h_ = hi - floor_;
    if (!(h_ > 500)) return invalid_argument("measure: the body is under 500 mm tall; is it a standing body in mm, Y up?");
    // The surface-path structures (a tenth of the work) are built beside the
    // landmark search, which needs them only for the lengths at the end.
    paths_ready_ = std::async(std::launch::async, [this] { paths_.emplace(mesh_); });
    slicer_.emplace(mesh_, lo, hi, opt_.step_mm);
    RETURN_IF_ERROR(find_axis());
    RETURN_IF_ERROR(find_crotch());
    for (int s : {1, -1}) RETURN_IF_ERROR(find_armpit(s));
    RETURN_IF_ERROR(find_neck());
    for (int s : {1, -1}) RETURN_IF_ERROR(find_side_neck(s));
    for (int s : {1, -1}) RETURN_IF_ERROR(find_shoulder(s));
    find_neck_points();
    find_torso_levels();
    measure_heights();
    measure_torso();
    for (int s : {1, -1}) knee_[s > 0 ? 0 : 1] = find_knee(s);
    for (int s : {1, -1}) measure_leg(s);
    for (int s : {1, -1}) measure_arm(s);
    measure_lengths();
    find_head_axis();
    find_stance();
    return Status();
  }

 private:
  static std::string side(int s) { return s > 0 ? "left" : "right"; }
  double at(double fraction) const { return floor_ + fraction * h_; }
  // The cut at y, remembered: the searches revisit the same levels (both legs,
  // several windows).
  const std::vector<Ring>& rings(double y) const {
    const auto key = static_cast<int64_t>(std::llround(y * 64));
    auto it = ring_cache_.find(key);
    if (it == ring_cache_.end()) it = ring_cache_.emplace(key, slicer_->rings(static_cast<double>(key) / 64)).first;
    return it->second;
  }
  // The cuts a walk from y0 towards y1 in steps of `step` (either sign) will ask for,
  // made ahead on every core: the searches and profiles walk hundreds of levels and
  // each cut stands alone. (The same levels as the walk's own loop, to the bit.)
  void prefetch(double y0, double y1, double step) const {
    std::vector<int64_t> keys;
    for (double y = y0; step > 0 ? y <= y1 : y >= y1; y += step) {
      const auto key = static_cast<int64_t>(std::llround(y * 64));
      if (!ring_cache_.count(key)) keys.push_back(key);
    }
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    std::vector<std::vector<Ring>> made(keys.size());
    tbb::parallel_for(size_t{0}, keys.size(),
                      [&](size_t i) { made[i] = slicer_->rings(static_cast<double>(keys[i]) / 64); });
    for (size_t i = 0; i < keys.size(); ++i) ring_cache_.emplace(keys[i], std::move(made[i]));
  }

  void landmark(const std::string& name, const Eigen::Vector3d& p) {
    float confidence = 1;
    if (mesh_.confidence.size() == mesh_.vertices.size()) {
      const Vec3f q = p.cast<float>();
      float best = std::numeric_limits<float>::infinity();
      for (size_t i = 0; i < mesh_.vertices.size(); ++i)
        if (const float d = (mesh_.vertices[i] - q).squaredNorm(); d < best) best = d, confidence = mesh_.confidence[i];
    }
    out_->landmarks.push_back({name, p, confidence});
  }
  Eigen::Vector3d lm(const std::string& name) const { return out_->landmark(name)->position; }

  // --- landmarks -------------------------------------------------------------

  Status find_axis() {
    const std::vector<Ring>& r = rings(at(0.55));
    const Ring* best = nullptr;
    for (const Ring& x : r)
      if (!best || x.girth > best->girth) best = &x;
    if (!best) return not_found("measure: nothing at 55 % of the height; is the body standing on the floor?");
    xc_ = best->centroid.x();
    zc_ = best->centroid.z();
    return Status();
  }

  // Up from where two parts join at height y: where the joined loop crosses the
  // vertical plane X = x on invented surface only, front and back (hole filling's
  // bridge across a gap no camera sees into), the first level above which the
  // crossing is measured skin: where the crossing's confidence (front or back, the
  // higher), sampled every quarter millimetre and averaged over kBridgeWindowMm
  // around the level, reaches kMeasuredConfidence (interpolated), within `reach`.
  // Else y: the join is measured, or the bridge reaches farther than that (wholly
  // unseen). Where the bridge meets the skin, the crossing runs in and out of the
  // filled patch, and islands of measured surface 0.5-1.25 mm tall lie below the
  // skin, up to 5 mm below it (tiered rig: male_average, male_heavy, female_heavy).
  // The first measured level, walked in whole millimetres, stepped over such an
  // island on one scan and not on its repeat (male_average's crotch heights 2.0 mm
  // apart); walked finely, it took the island 5 mm under male_heavy's crotch. Over
  // the window an island counts for its share, and a sharp edge of skin is read
  // where it is.
  double above_bridge(double y, double x, double reach) {
    const auto confidence = [&](double yy) -> double {
      const Ring* m = midline(rings(yy), xc_);
      return m ? m->crossing_confidence(x) : 1.0;
    };
    if (confidence(y + 0.5) >= kMeasuredConfidence) return y;
    constexpr double kStep = 0.25;
    const auto half = static_cast<size_t>(std::lround(kBridgeWindowMm / 2 / kStep));
    // From y + 0.5 up (the join's own level may lie just under the joined loop);
    // below it the window sees what y + 0.5 has, invented surface.
    const double y0 = y + 0.5;
    prefetch(y0, y0 + reach + kBridgeWindowMm, kStep);
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

  // Up from a join at y (legs or arm and flank), the level where the midline loop's
  // crossing of the plane X = x has grown `span` long front to back (interpolated
  // between 1 mm cuts), within `reach`; y if it never does.
  double widened(double y, double x, double span, double reach) {
    const auto length = [&](double yy) {
      double f = 0, b = 0;
      const Ring* m = midline(rings(yy), xc_);
      return m && m->crossing_z(x, &f, &b) ? std::abs(f - b) : 0.0;
    };
    prefetch(y, y + reach, 1);
    double at = y + 0.5, prev = length(at);
    if (prev >= span) return y;
    for (double yy = at + 1; yy <= y + reach; yy += 1) {
      const double l = length(yy);
      if (l >= span) return at + (span - prev) / (l - prev) * (yy - at);
      at = yy, prev = l;
    }
    return y;
  }

  Status find_crotch() {
    auto merged = [&](double y) { return midline(rings(y), xc_) != nullptr; };
    const double step = 5;
    double prev = at(0.25);
    if (merged(prev)) return not_found("measure: the legs are not apart at a quarter of the height; stand with feet apart");
    prefetch(prev + step, at(0.55), step);
    for (double y = prev + step; y <= at(0.65); y += step) {
      if (merged(y)) {
        crotch_y_ = bisect(prev, y, merged);
        // Where the thighs nearly touch no camera sees between them, and the surface
        // bridges the gap below the real crotch (male_heavy, tiered rig: 21 mm below
        // it, where the thighs are still 17 mm apart). The bridge is filled, the real
        // crotch's front and back are seen: up from the first join, the first level
        // whose midline crossings are measured skin, within 5 % of the height.
        crotch_y_ = above_bridge(crotch_y_, xc_, 0.05 * h_);
        // The surface also rounds the corner where measured thighs meet: it closes
        // their gap a few mm below the crotch (female_average, tiered rig: 5.4 mm,
        // where the thighs are 12 mm apart), and there the join is a narrow saddle,
        // 5-30 mm front to back, that grows 4-10 mm per mm of height. A true
        // crotch's floor is 15-70 mm long where the legs first meet. The crotch is
        // where the join has grown kJoinDepth of the height long (25 mm on most
        // bodies): on the true bodies 0.5-1.0 mm above the first join, on that scan
        // 5.6 mm (crotch -5.4 -> -1.5 mm, thighs -6.3/-6.5 -> -2.6/-3.0).
        crotch_y_ = widened(crotch_y_, xc_, kJoinDepth * h_, 0.02 * h_);
        const std::vector<Ring>& r = rings(crotch_y_ + 0.5);
        double f = zc_, b = zc_;
        if (const Ring* m = midline(r, xc_)) m->crossing_z(xc_, &f, &b);
        landmark("crotch", {xc_, crotch_y_, 0.5 * (f + b)});
        return Status();
      }
      prev = y;
    }
    return not_found("measure: no crotch found between 25 % and 65 % of the height");
  }

  // The arm's loop on side s in a cut: at least 5 % of the height round (a wrist is
  // over 9 %). A scrap of surface a coarse scan leaves beside the hip is no arm.
  const Ring* arm_ring(const std::vector<Ring>& r, int s) const { return side_ring(r, xc_, s, true, 0.05 * h_); }

  Status find_armpit(int s) {
    auto arm = [&](double y) { return arm_ring(rings(y), s) != nullptr; };
    // Upwards from just above the crotch, the first run of cuts with the arm apart
    // from the body that is at least 4 % of the height long (a scrap that comes and
    // goes is not); the armpit is where that run ends.
    const double step = 5;
    double y = crotch_y_ + 0.03 * h_, first = y, last = y;
    prefetch(y, at(0.8), step);
    for (;; y += step) {
      while (y < at(0.9) && !arm(y)) y += step;
      if (y >= at(0.9))
        return not_found("measure: no " + side(s) + " arm apart from the body; hold the arms away from the sides");
      first = last = y;
      for (y += step; y < at(0.95) && arm(y); y += step) last = y;
      if (last - first >= 0.04 * h_) break;
    }
    double armpit = bisect(y, last, arm);
    arm_apart_y_[s > 0 ? 0 : 1] = armpit;
    // The armpit: halfway across the last gap between arm and torso.
    const std::vector<Ring>& r = rings(armpit - 0.5);
    const Ring* a = arm_ring(r, s);
    const Ring* t = midline(r, xc_);
    Eigen::Vector3d p(xc_ + s * 0.1 * h_, armpit, zc_);
    if (a && t) {
      double best = kInf;
      for (const Eigen::Vector3d& u : a->points)
        for (const Eigen::Vector3d& v : t->points)
          if ((u - v).squaredNorm() < best) best = (u - v).squaredNorm(), p = 0.5 * (u + v);
    }
    // As at the crotch: no camera sees the top of the armpit, and hole filling can
    // bridge the gap between arm and flank below it (male_average, tiered rig: the
    // gap is gone 9 mm below the truth's junction). Where the joined loop crosses
    // the gap's plane on invented surface only, front and back, the armpit is the
    // first level above where one of those crossings is measured skin, if that is
    // within 1 % of the height. Farther up (the thesis rig's level cameras see no
    // armpit at all) the top is wholly unseen, and the armpit stays at the join.
    armpit = above_bridge(armpit, p.x(), 0.01 * h_);
    // The chest is cut under the armpit's vault: where the join of arm and flank has
    // grown kJoinDepth of the height long front to back, as at the crotch. A scan's
    // join narrows to a saddle a few mm below the true armpit; how far down depends
    // on the noise, and the chest girth moved 6 mm between two scans of one body
    // (tiered rig, male_average; now under 1). The armpit itself stays at the join:
    // the neck and shoulder searches start from it.
    vault_y_[s > 0 ? 0 : 1] = widened(armpit, p.x(), kJoinDepth * h_, 0.02 * h_);
    p.y() = armpit;
    armpit_y_[s > 0 ? 0 : 1] = armpit;
    landmark("armpit_" + side(s), p);
    return Status();
  }

  // Triangles with a corner within r of c (for the tilted cuts).
  // (Among `among`, when given: a subset known to hold them all.)
  std::vector<uint32_t> triangles_near(const Eigen::Vector3d& c, double r,
                                       const std::vector<uint32_t>& among = {}) const {
    std::vector<uint32_t> out;
    const float r2 = static_cast<float>(r * r);
    const Vec3f cf = c.cast<float>();
    const size_t n = among.empty() ? mesh_.triangles.size() : among.size();
    for (size_t i = 0; i < n; ++i) {
      const uint32_t t = among.empty() ? static_cast<uint32_t>(i) : among[i];
      for (uint32_t v : mesh_.triangles[t])
        if ((mesh_.vertices[v] - cf).squaredNorm() <= r2) {
          out.push_back(t);
          break;
        }
    }
    return out;
  }

  Status find_neck() {
    const double ya = std::max(armpit_y_[0], armpit_y_[1]);
    std::vector<double> ys, gs;
    std::vector<Eigen::Vector3d> cs;
    prefetch(ya + 0.04 * h_, floor_ + h_ - 0.09 * h_, 2);
    for (double y = ya + 0.04 * h_; y <= floor_ + h_ - 0.09 * h_; y += 2) {
      const std::vector<Ring>& r = rings(y);
      if (const Ring* m = midline(r, xc_)) ys.push_back(y), gs.push_back(m->girth), cs.push_back(m->centroid);
    }
    if (ys.empty()) return not_found("measure: no neck found between the armpits and the head");
    // The neck is narrowest over several mm, and the middle of the samples within
    // 1 mm of the narrowest slid 2.2 mm between a scan and its true body, the tilted
    // neck girth 1-2 mm per mm with it. The middle of the flat minimum, taken as the
    // wrist's, moves less; that run's middle is the fallback.
    const size_t k = arg_extreme(gs, false), mid = settle(gs, k, 1.0);
    neck_y_ = ys[mid], neck_c_ = cs[mid];
    if (const std::optional<double> y = flat_bottom_middle(ys, gs, k, kFlatRiseMm))
      if (const Ring* m = midline(rings(*y), xc_)) neck_y_ = *y, neck_c_ = m->centroid;
    // The narrowest tape is flat over several mm, so its length holds still where
    // its level slides.
    neck_r_ = gs[k] / (2 * M_PI);
    landmark("neck_level", neck_c_);
    return Status();
  }

  Status find_side_neck(int s) {
    // The neck's base on side s: the level where the front outline (the midline
    // loop's half-width on that side) has flared to kNeckBaseWidth times the radius
    // of the neck's narrowest horizontal tape, interpolated between cuts.
    const double target = kNeckBaseWidth * neck_r_;
    const double ya = std::max(armpit_y_[0], armpit_y_[1]);
    double y_prev = neck_y_, w_prev = -kInf, y_base = kInf;
    prefetch(neck_y_, ya, -2);
    for (double y = neck_y_; y > ya && y_base == kInf; y -= 2) {
      const Ring* m = midline(rings(y), xc_);
      if (!m) break;
      double w = -kInf;
      for (const Eigen::Vector3d& p : m->points) w = std::max(w, s * (p.x() - xc_));
      if (w >= target) y_base = w_prev == -kInf ? y : y_prev + (target - w_prev) / (w - w_prev) * (y - y_prev);
      y_prev = y, w_prev = w;
    }
    if (y_base == kInf) return not_found("measure: no " + side(s) + " shoulder below the neck");
    const Ring* m = midline(rings(y_base), xc_);
    if (!m) return not_found("measure: no " + side(s) + " side of the neck at its base");
    landmark("side_neck_point_" + side(s),
             middle_of_extreme(m->points, {static_cast<double>(s), 0, 0}, Eigen::Vector3d::UnitZ(), kNeckSideBand));
    return Status();
  }

  Status find_shoulder(int s) {
    const Eigen::Vector3d snp = lm("side_neck_point_" + side(s));
    const double w_snp = s * (snp.x() - xc_);
    const double ya = arm_apart_y_[s > 0 ? 0 : 1];
    // Below the side neck point: the head overhangs the neck's side.
    const double y_hi = snp.y() + 0.01 * h_;
    const double bin = 3, u0 = w_snp + 0.01 * h_, u1 = w_snp + 0.25 * h_;
    const auto nb = static_cast<size_t>((u1 - u0) / bin) + 1;
    // The top outline seen from the front, exact on the mesh: in each vertical plane
    // X = const through a column's centre, the section's points are where the mesh's
    // edges cross it. (The highest vertex per column dropped 15-40 mm wherever the
    // 107k-triangle true bodies have no vertex near the top in a 3 mm column.)
    // `at`: the columns' centres, or one plane's offset.
    auto sections = [&](const std::function<double(size_t)>& at, size_t count) {
      std::vector<std::vector<Eigen::Vector3d>> column(count);
      const double c_lo = at(0), c_hi = at(count - 1), step = count > 1 ? at(1) - at(0) : 1;
      for (const auto& t : mesh_.triangles)
        for (int e = 0; e < 3; ++e) {
          const Eigen::Vector3d p = mesh_.vertices[t[e]].cast<double>(), q = mesh_.vertices[t[(e + 1) % 3]].cast<double>();
          if (std::max(p.y(), q.y()) < ya || std::min(p.y(), q.y()) > y_hi) continue;
          const double up = s * (p.x() - xc_), uq = s * (q.x() - xc_);
          const double lo = std::max(std::min(up, uq), c_lo), hi = std::min(std::max(up, uq), c_hi);
          if (lo > hi || up == uq) continue;
          for (auto c = static_cast<size_t>(std::max(0.0, std::ceil((lo - c_lo) / step))); c < count && at(c) <= hi; ++c) {
            const Eigen::Vector3d x = p + ((at(c) - up) / (uq - up)) * (q - p);
            if (x.y() >= ya && x.y() <= y_hi) column[c].push_back(x);
          }
        }
      return column;
    };
    const std::vector<std::vector<Eigen::Vector3d>> column = sections([&](size_t c) { return u0 + (c + 0.5) * bin; }, nb);
    std::vector<double> us = {w_snp}, tops = {snp.y()};
    const double y_arm = ya + 0.25 * (snp.y() - ya);  // well down the arm
    for (size_t c = 0; c < nb && tops.back() > y_arm; ++c) {
      if (column[c].empty()) continue;
      double top = -kInf;
      for (const Eigen::Vector3d& x : column[c]) top = std::max(top, x.y());
      us.push_back(u0 + (c + 0.5) * bin), tops.push_back(top);
    }
    if (us.size() < 4) return not_found("measure: no " + side(s) + " shoulder outline");
    // The shoulder's corner bulges above the chord from the neck to where the outline
    // is well down the arm (that end interpolated between columns), refined to the
    // vertex of a parabola fitted to the height above the chord: the outline is a
    // smooth curve there, and its highest sample above the chord moved 6-10 mm under
    // +-0.5 mm of skin noise. Over 1 % of the height either side the vertex still
    // moved 9.5 mm under skin noise (male_average, one seed of five) and 4-8 mm
    // between two scans of one body on the thesis rig; over 2 %, centred on the
    // highest sample, 0.6-1.4 mm RMS across the body under smooth skin noise of
    // 0.25 mm. Since session 25 the fit's weights fall smoothly to zero kCornerHalf
    // of the height either side of its own vertex (settled_vertex): 0.4-0.7 mm RMS,
    // and the biacromial breadth 0.4-0.8 mm RMS on six bodies (was 0.6-2.0). That
    // vertex lies 3-5 mm nearer the neck than the narrower fit's (biacromial breadth
    // 6-10 mm smaller), 17-34 mm outside the MakeHuman shoulder joint's centre.
    const auto [k, u] = refined_corner(us, tops, y_arm, kCornerHalf * h_);
    if (k == 0) {
      landmark("shoulder_point_" + side(s), snp);
      return Status();
    }
    // The top of the shoulder runs front to back: its middle there, between the
    // section's points (the nearest of them moved the point 1.1-2.7 mm RMS front to
    // back under smooth skin noise, on a mesh with a point every 5-10 mm; now 0.3-0.8).
    // (A copy: clang before 16 cannot capture a structured binding.)
    const double corner = u;
    const std::vector<std::vector<Eigen::Vector3d>> at_u = sections([corner](size_t) { return corner; }, 1);
    landmark("shoulder_point_" + side(s),
             middle_of_extreme(at_u[0].empty() ? column[std::min(nb - 1, static_cast<size_t>((us[k] - u0) / bin))] : at_u[0],
                               Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), kRidgeBand, true));
    return Status();
  }

  // The stance: the distance between the legs' centres at the ankles, each leg the
  // longest loop wholly on its side of the midline (a scrap the surface left by a
  // foot is not it), read at the first level from kAnkleLevel up where both are.
  void find_stance() {
    for (double f = kAnkleLevel; f <= kAnkleLevel + 0.03 + 1e-9; f += 0.01) {
      const std::vector<Ring>& r = rings(at(f));
      const Ring* legs[2] = {nullptr, nullptr};
      for (const Ring& x : r) {
        if (x.spans_x(xc_)) continue;
        const Ring*& l = legs[x.centroid.x() > xc_ ? 0 : 1];
        if (!l || x.girth > l->girth) l = &x;
      }
      if (legs[0] && legs[1]) {
        out_->posture.ankle_distance_mm = (legs[0]->centroid - legs[1]->centroid).norm();
        return;
      }
    }
  }

  // The head's axis: a line through the centres of the cranium's cuts (the top
  // 1.5-6 % of the height: above the face and the jaw, whose shape would tilt
  // the line on a level head), as tilts from the vertical.
  void find_head_axis() {
    std::vector<Eigen::Vector3d> c;
    const double y0 = floor_ + h_ - 0.06 * h_, y1 = floor_ + h_ - 0.015 * h_;
    prefetch(y0, y1, 2);
    for (double y = y0; y <= y1; y += 2)
      if (const Ring* m = midline(rings(y), xc_)) c.push_back(m->centroid);
    if (c.size() < 5) return;
    const Eigen::Vector3d d = fit_line(c, 0, c.size()).second;
    out_->posture.head_tilt_deg = std::atan2(d.z(), d.y()) * 180 / M_PI;
    out_->posture.head_side_tilt_deg = std::atan2(d.x(), d.y()) * 180 / M_PI;
  }

  void find_neck_points() {
    const double y_snp = 0.5 * (lm("side_neck_point_left").y() + lm("side_neck_point_right").y());
    double f = neck_c_.z(), b = neck_c_.z();
    const std::vector<Ring>& rr = rings(y_snp);
    if (const Ring* m = midline(rr, xc_)) m->crossing_z(xc_, &f, &b);
    landmark("back_neck_point", {xc_, y_snp, b});
    std::vector<Eigen::Vector2d> curve;  // (y, front z), top down
    prefetch(neck_y_, y_snp - 0.08 * h_, -2);
    for (double y = neck_y_; y >= y_snp - 0.08 * h_; y -= 2) {
      const std::vector<Ring>& r = rings(y);
      double fz = 0, bz = 0;
      const Ring* m = midline(r, xc_);
      if (m && m->crossing_z(xc_, &fz, &bz)) curve.emplace_back(y, fz);
    }
    Eigen::Vector3d front(xc_, y_snp - 0.03 * h_, neck_c_.z());
    if (curve.size() >= 3) {
      // The notch: the front's deepest point behind the chord from neck to chest. The
      // profile's bottom is flat over 10-15 mm, and its deepest sample moved 6 mm under
      // +-0.5 mm of skin noise: refined to the vertex of a parabola fitted to the depth
      // over 2 % of the height either side, as the knee.
      const Notch notch = deepest_behind_chord(curve, 0.02 * h_);
      front = {xc_, curve[notch.k].x(), curve[notch.k].y()};
      if (const std::optional<double> yv = notch.vertex_y) {
        for (size_t i = 0; i + 1 < curve.size(); ++i)
          if (curve[i].x() >= *yv && *yv >= curve[i + 1].x()) {
            const double t = (curve[i].x() - *yv) / (curve[i].x() - curve[i + 1].x());
            front = {xc_, *yv, curve[i].y() + t * (curve[i + 1].y() - curve[i].y())};
          }
      }
    }
    landmark("front_neck_point", front);
  }

  void find_torso_levels() {
    const double ya = std::min(armpit_y_[0], armpit_y_[1]);
    // The level where f of the midline loop is extreme between y0 and y1: the middle
    // of the run within `tol` of the extreme sample; with `refine` > 0, the vertex of
    // a parabola fitted over `refine` either side of it, fitted a second time round
    // the sample nearest the first vertex (a flat extreme's middle moves with the
    // skin's noise, the vertex much less); with `settled`, the vertex of a parabola
    // whose weights fall to zero `refine` either side of the vertex itself
    // (settled_vertex), that fit where it fails.
    // f of the midline loop every 2 mm from y0 to y1, where there is one: (levels, values).
    auto sample = [&](double y0, double y1, const std::function<double(const Ring&)>& f) {
      std::pair<std::vector<double>, std::vector<double>> out;
      prefetch(y0, y1, 2);
      for (double y = y0; y <= y1; y += 2)
        if (const Ring* m = midline(rings(y), xc_)) out.first.push_back(y), out.second.push_back(f(*m));
      return out;
    };
    auto profile = [&](double y0, double y1, const std::function<double(const Ring&)>& f, bool largest, double tol,
                       double fallback, double refine = 0, bool settled = false, size_t bump = 0) {
      auto [ys, vs] = sample(y0, y1, f);
      if (ys.empty()) return fallback;
      if (bump > 0) vs = despiked(vs, bump, tol);
      size_t k = settle(vs, arg_extreme(vs, largest), tol);
      if (settled && refine > 0)
        if (const std::optional<double> v = settled_vertex(ys, vs, k, refine, !largest)) return *v;
      double at_y = ys[k];
      for (int pass = 0; refine > 0 && pass < 2; ++pass) {
        const std::optional<double> v = parabola_vertex(ys, vs, k, refine, !largest);
        if (!v) break;
        at_y = *v;
        for (size_t i = 0; i < ys.size(); ++i)
          if (std::abs(ys[i] - *v) < std::abs(ys[k] - *v)) k = i;
      }
      return at_y;
    };
    // Bust: the chest's most forward point. The front's profile is flat over the
    // breast's apex, and its middle sat 3.5 mm low on a tiered scan of female_average,
    // where the tape grows 3 mm per mm (bust girth -8.6 mm): refined over 1 % of the
    // height either side. A heavy man's front is flat within 0.5 mm over 40 mm of
    // height, and a bump 1-3 mm proud and one or two 2 mm samples tall (a stray
    // stripe's skin on the midline) was the foremost: male_heavy's level moved 34 mm
    // between two replays of one scan's stripes (bust girth -1.5 and -5.5 mm). A
    // sample more than the settling tolerance (0.5 mm) off the median of the
    // kBustBumpSamples either side takes that median (despiked).
    //
    // And that flat front is flat further still: within 1.5 mm of its foremost over
    // 70-80 mm of height (a woman's apex 15-24 mm, male_average's 30), and a
    // parabola over 1 % of the height either side followed ripples of a few tenths
    // of a millimetre across it. Replays of one still male_heavy scan whose sway
    // estimates differed by that much put the level 1118-1138 mm up, the bust girth
    // 0.0 to -6.4 mm off the truth. Where the front falls kBustTopDropMm below its
    // foremost on both sides within the search, over more than 2 % of the height,
    // the level is the vertex of a parabola whose weights reach zero half that span
    // either side of itself (settled_vertex), over the whole top.
    {
      const double y0 = ya - 0.12 * h_, y1 = ya - 0.01 * h_;
      const auto front = [](const Ring& m) { return m.z_max; };
      auto [ys, vs] = sample(y0, y1, front);
      std::optional<double> level;
      if (!ys.empty()) level = flat_top_vertex(ys, despiked(vs, kBustBumpSamples, 0.5), kBustTopDropMm, 0.02 * h_);
      bust_y_ = level ? *level : profile(y0, y1, front, true, 0.5, ya - 0.06 * h_, 0.01 * h_, false, kBustBumpSamples);
    }
    {
      const std::vector<Ring>& r = rings(bust_y_);
      const Ring* m = midline(r, xc_);
      for (int s : {1, -1}) {
        Eigen::Vector3d p(xc_ + s * 0.05 * h_, bust_y_, zc_);
        double z = -kInf;
        if (m)
          for (const Eigen::Vector3d& q : m->points)
            if (s * (q.x() - xc_) > 0.01 * h_ && q.z() > z) z = q.z(), p = q;
        // Across the breast the front is flat at the apex's level (within 0.5 mm over
        // 40 mm on female_average), and its foremost point jumped up to 23 mm from
        // side to side under a quarter of a millimetre of skin noise: the point is the
        // centroid of the front within kBustBandMm of the foremost, weighted by how far
        // inside that band it lies, on the front where it crosses that X.
        double sw = 0, sx = 0, f = 0, b = 0;
        if (m)
          for (const Eigen::Vector3d& q : m->points)
            if (const double w = q.z() - (z - kBustBandMm); s * (q.x() - xc_) > 0.01 * h_ && w > 0)
              sw += w, sx += w * q.x();
        if (sw > 0 && m->crossing_z(sx / sw, &f, &b)) p = {sx / sw, bust_y_, f};
        landmark("bust_point_" + side(s), p);
      }
    }
    // Under-bust: below the bust points, the front's deepest point behind the chord.
    {
      const double xb = 0.5 * (lm("bust_point_left").x() + lm("bust_point_right").x());
      const double xs = 0.5 * (lm("bust_point_left").x() - lm("bust_point_right").x());
      // The front's mean over kUnderBustColumns columns either side, kUnderBustStep
      // of the height apart, centred on each bust point's X (one column each until
      // session 26: female_slim_tall's under-bust girth moved 1.7 mm RMS under smooth
      // skin noise, now 0.9). A level where a column misses the front is left out.
      std::vector<Eigen::Vector2d> curve;
      prefetch(bust_y_, bust_y_ - 0.1 * h_, -2);
      for (double y = bust_y_; y >= bust_y_ - 0.1 * h_; y -= 2) {
        const std::vector<Ring>& r = rings(y);
        const Ring* m = midline(r, xc_);
        double f = 0, b = 0, f2 = 0, b2 = 0, sum = 0;
        int n = 0;
        for (int j = -kUnderBustColumns; m && j <= kUnderBustColumns; ++j) {
          const double o = j * kUnderBustStep * h_;
          if (!m->crossing_z(xb + xs + o, &f, &b) || !m->crossing_z(xb - xs - o, &f2, &b2)) break;
          sum += f + f2, n += 2;
        }
        if (n == 2 * (2 * kUnderBustColumns + 1)) curve.emplace_back(y, sum / n);
      }
      underbust_y_ = bust_y_ - 0.05 * h_;
      if (curve.size() >= 3) {
        const Notch notch = deepest_behind_chord(curve, 0.02 * h_);
        underbust_y_ = curve[notch.k].x();
        underbust_fold_ = notch.depth < 0;
        // A shallow fold (a man's: 0-6 mm behind the chord, against 17-46 mm under a
        // woman's breast) is flat at the bottom, and its deepest sample is the skin
        // noise's: it moved 10 mm between two scans of male_average. There the vertex
        // of a parabola over 2 % of the height either side stands (within 3 mm on four
        // scans). A deep fold is a crease, steep above and gentle below, where that
        // vertex would slide 6-12 mm down the ribs. There the deepest sample stood
        // until session 24, in the profile's 2 mm steps, and the tape, steep across
        // the crease, jumped with it (female_slim_tall: 2.6 mm RMS under smooth skin
        // noise of 0.25 mm); now the centroid of the crease's bottom kCreaseDepthMm
        // deep (1.7 mm RMS; female_average 1.3 → 0.8).
        if (notch.depth > -kShallowFoldMm && notch.vertex_y) underbust_y_ = *notch.vertex_y;
        if (notch.depth <= -kShallowFoldMm) underbust_y_ = minimum_centroid(notch.ys, notch.depths, notch.k, kCreaseDepthMm);
        breast_ = breast_reach(-notch.depth);
      }
      landmark("underbust_front_point", {xc_, underbust_y_, front_z(underbust_y_)});
    }
    // The bust girth's level. Over a breast the tape grows 2-3 mm per mm of height
    // through the apex's level, to its fullest 6-11 mm above, and the apex is flat
    // (its front within 0.3 mm over 5 mm): a tiered scan of female_average put the
    // girth at the apex 3.0 mm apart between two scans, their fullest readings 0.1.
    // A tape is read at its fullest across the prominence (EN 13402-1: "maximum
    // horizontal girth ... across the bust prominence"): the largest girth within
    // kBustReachOfHeight of the apex's level, below the armpits, every 2 mm and then
    // every 0.5 mm round the largest. A man's chest rises into the armpits with no
    // such fullest level, and the crease beneath tells them apart (17-46 mm deep
    // under the shipped bodies' breasts, a man's fold 0-6): a man's is read at the
    // apex's level, and between the two the reach grows with the crease's depth
    // (breast_reach).
    bust_girth_y_ = bust_y_;
    if (breast_ > 0) {
      const double reach = breast_ * kBustReachOfHeight * h_;
      const double lo = bust_y_ - reach, hi = std::max(bust_y_, std::min(bust_y_ + reach, ya - 0.01 * h_));
      const auto [ys, vs] = sample(lo, hi, [](const Ring& m) { return m.girth; });
      if (!ys.empty()) {
        const size_t k = arg_extreme(vs, true);
        double best = vs[k];
        bust_girth_y_ = ys[k];
        for (double y = ys[k] - 1.5; y <= ys[k] + 1.5; y += 0.5)
          if (const Ring* m = y >= lo && y <= hi ? midline(rings(y), xc_) : nullptr; m && m->girth > best)
            best = m->girth, bust_girth_y_ = y;
      }
    }
    // Hip: the buttocks' greatest backward projection.
    // The band of the back within 0.5 mm of the backmost is 30-40 mm tall on the heavy
    // bodies, and its middle moved with the skin noise (hip height +6.8 and +9.2 mm
    // on female_heavy and male_heavy, tiered rig): refined over 2 % of the height
    // either side, as at the knee, until session 25; now the vertex of a parabola
    // whose weights fall to zero kHipHalf of the height either side of itself: under
    // smooth skin noise of 0.25 mm the hip height moved 0.7-1.6 mm RMS over six
    // bodies, now 0.5-1.05, and the hip girth 0.7-1.1, now 0.5-1.0.
    hip_y_ = profile(crotch_y_ + 0.01 * h_, crotch_y_ + 0.16 * h_, [](const Ring& m) { return m.z_min; }, false, 0.5,
                     crotch_y_ + 0.08 * h_, kHipHalf * h_, true);
    // The hip's back point is on the tape at the centre back: the tape spans the
    // cleft between the buttocks at their backmost, wherever on either side that is.
    Eigen::Vector3d hip_point(xc_, hip_y_, zc_);
    if (const Ring* m = midline(rings(hip_y_), xc_)) hip_point.z() = m->z_min;
    landmark("hip_back_point", hip_point);
    // Waist: the narrowest torso between hip and under-bust. Where the front has no
    // fold below the bust (a belly's dome, whose top is the most forward point:
    // male_heavy), the under-bust is the bust itself, and the flat top moves it
    // 33 mm between a scan and the truth; the waist's window then runs to 70 % of
    // the height (male_heavy, tiered rig: waist height -36.8 mm, girth +16.6).
    double lo = std::max(hip_y_ + 0.04 * h_, at(0.55)),
           hi = underbust_fold_ ? std::min(underbust_y_ - 0.02 * h_, at(0.70)) : at(0.70);
    if (lo >= hi) lo = hip_y_ + 0.04 * h_, hi = underbust_y_ - 0.02 * h_;
    // The level is the centroid of the girth profile's dip kWaistDepthMm deep: the
    // middle of the run within 2 mm of the narrowest cut moved up to 5 mm under a
    // quarter of a millimetre of skin noise, in 2 mm steps (measure_benchmark
    // --noise-study: female_average's waist height 2.1 mm RMS, now 0.75).
    {
      const auto [ys, vs] = sample(lo, hi, [](const Ring& m) { return m.girth; });
      waist_y_ = ys.empty() ? 0.5 * (lo + hi) : minimum_centroid(ys, vs, arg_extreme(vs, false), kWaistDepthMm);
    }
    double f = zc_, b = zc_;
    const std::vector<Ring>& rr = rings(waist_y_);
    if (const Ring* m = midline(rr, xc_)) m->crossing_z(xc_, &f, &b);
    landmark("waist_back_point", {xc_, waist_y_, b});
    landmark("waist_front_point", {xc_, waist_y_, f});
  }

  double front_z(double y) const {
    double f = zc_, b = zc_;
    const std::vector<Ring>& rr = rings(y);
    if (const Ring* m = midline(rr, xc_)) m->crossing_z(xc_, &f, &b);
    return f;
  }

  // --- measurements ----------------------------------------------------------

  void add(BodyMeasurement m) {
    for (const std::string& l : m.landmarks)
      if (const BodyLandmark* b = out_->landmark(l)) m.min_confidence = std::min(m.min_confidence, b->confidence);
    out_->measurements.push_back(std::move(m));
  }
  void skip(const std::string& name, const std::string& why) { out_->skipped.push_back(name + ": " + why); }

  // A height: the level of p above the floor, drawn as a plumb line up to p.
  void height(const std::string& name, const std::string& label, const std::string& clause,
              std::vector<std::string> landmarks, const Eigen::Vector3d& p, const std::string& definition) {
    BodyMeasurement m;
    m.name = name, m.label = label, m.iso_clause = clause, m.kind = "height";
    m.value_mm = p.y() - floor_;
    m.path = {Eigen::Vector3d(p.x(), floor_, p.z()), p};
    m.landmarks = std::move(landmarks);
    m.definition = definition;
    add(std::move(m));
  }

  void girth(const std::string& name, const std::string& label, const std::string& clause, const StatusOr<Girth>& g,
             std::vector<std::string> landmarks, const std::string& definition) {
    if (!g.ok()) {
      skip(name, g.status().message());
      return;
    }
    BodyMeasurement m;
    m.name = name, m.label = label, m.iso_clause = clause, m.kind = "girth";
    m.value_mm = g->value_mm;
    m.path = g->tape;
    m.closed = true;
    m.loop = g->loop;
    m.plane = g->plane;
    m.landmarks = std::move(landmarks);
    m.definition = definition;
    m.min_confidence = g->min_confidence;
    add(std::move(m));
  }

  StatusOr<Girth> level_girth(double y, const Eigen::Vector3d& near) const { return slicer_->girth(y, near); }

  void measure_heights() {
    landmark("top_of_head", top_);
    height("stature", "Stature", "5.1.1", {"top_of_head"}, top_, "top of the head above the floor");
    height("cervical_height", "Cervical height", "", {"back_neck_point"}, lm("back_neck_point"),
           "back neck point above the floor");
    height("crotch_height", "Inside leg length (crotch height)", "5.1.15", {"crotch"}, lm("crotch"),
           "crotch above the floor");
  }

  void measure_torso() {
    auto near = [&](double y) { return Eigen::Vector3d(xc_, y, zc_); };
    // Neck girth: the smallest loop round the neck over planes tilted forward and back.
    {
      const std::vector<uint32_t> tris = triangles_near(neck_c_, 0.08 * h_);
      StatusOr<Girth> best = not_found("no loop round the neck");
      auto cut = [&](double deg) {
        const double t = deg * M_PI / 180;
        Plane p{neck_c_, Eigen::Vector3d(0, std::cos(t), std::sin(t))};
        StatusOr<Girth> g = mesh_girth(mesh_, p, neck_c_, &tris);
        // Only a loop round the neck counts (a steep cut can leave the part of the
        // mesh searched, and a scrap of ear or chin would win).
        if (g.ok() && winds_round(g->loop, neck_c_, p.normal) && (!best.ok() || g->value_mm < best->value_mm))
          best = std::move(g), neck_tilt_ = deg;
      };
      for (double d = -40; d <= 40; d += 4) cut(d);
      const double centre = neck_tilt_;
      for (double d = centre - 3; d <= centre + 3; d += 1) cut(d);
      girth("neck_girth", "Neck girth", "5.3.2", best, {"neck_level"},
            "smallest girth round the neck, over planes through its narrowest level tilted up to 40 degrees forward "
            "or back (perpendicular to the neck's axis)");
    }
    // Neck base: the tape round the neck's base through its four points.
    {
      const std::vector<Eigen::Vector3d> via = {lm("back_neck_point"), lm("side_neck_point_left"),
                                                lm("front_neck_point"), lm("side_neck_point_right"),
                                                lm("back_neck_point")};
      surface("neck_base_girth", "Neck base girth", "5.3.3", via,
              {"back_neck_point", "side_neck_point_left", "front_neck_point", "side_neck_point_right"},
              "round the neck's base over the skin through the back, side and front neck points");
      if (!out_->measurements.empty() && out_->measurements.back().name == "neck_base_girth") {
        out_->measurements.back().kind = "girth";
        out_->measurements.back().closed = true;
      }
    }
    // Under the two armpits' vaults: 0.5 % of the height under their mean level.
    // Each vault is read where a scan's measured skin begins, a few mm off on either
    // side independently, and there the tape grows about 1 mm per mm of height; the
    // lower of the two put the chest's level 1.9 mm apart between two scans of
    // male_heavy (tiered rig; the mean 0.9, the girths 1.3 mm apart). Under the mean
    // the tape is under both vaults while they differ by less than 1 % of the
    // height. And below where either arm's own loop ends: above it, where the
    // armpit's top was a filled bridge (find_armpit), the cut's loop holds that arm
    // too.
    const double chest_y =
        std::min(0.5 * (vault_y_[0] + vault_y_[1]) - 0.005 * h_, std::min(arm_apart_y_[0], arm_apart_y_[1]) - 0.5);
    girth("chest_girth", "Chest girth", "5.3.6", level_girth(chest_y, near(chest_y)), {"armpit_left", "armpit_right"},
          "horizontal, just under the armpits' vaults (where the join of arm and flank is 1.5 % of the height deep)");
    girth("bust_girth", "Bust girth", "5.3.4", level_girth(bust_girth_y_, near(bust_girth_y_)),
          {"bust_point_left", "bust_point_right"},
          breast_ > 0 ? "horizontal, the fullest within 1.2 % of the height of the bust points' level (across the "
                        "breasts' prominence; less where the crease beneath is under 14 mm deep)"
                      : "horizontal, at the level of the chest's most forward point (no breast's crease beneath)");
    girth("underbust_girth", "Under-bust girth", "5.3.8", level_girth(underbust_y_, near(underbust_y_)),
          {"underbust_front_point"}, "horizontal, where the front turns in below the bust");
    girth("waist_girth", "Waist girth", "5.3.10", level_girth(waist_y_, near(waist_y_)),
          {"waist_back_point", "waist_front_point"},
          "horizontal, at the narrowest torso between hip level and under-bust (55-70 % of the height)");
    girth("hip_girth", "Hip girth", "5.3.13", level_girth(hip_y_, near(hip_y_)), {"hip_back_point"},
          "horizontal, at the level of the buttocks' greatest backward projection");
    {
      double best = -kInf, yb = hip_y_;
      prefetch(crotch_y_ + 0.01 * h_, waist_y_, 2);
      for (double y = crotch_y_ + 0.01 * h_; y <= waist_y_; y += 2) {
        const std::vector<Ring>& r = rings(y);
        if (const Ring* m = midline(r, xc_); m && m->girth > best) best = m->girth, yb = y;
      }
      girth("max_hip_girth", "Maximum hip girth", "5.3.14", level_girth(yb, near(yb)), {"crotch", "waist_back_point"},
            "horizontal, the largest between crotch and waist");
    }
    height("waist_height", "Waist height", "5.1.10", {"waist_back_point"}, lm("waist_back_point"),
           "waist level above the floor");
    height("hip_height", "Hip height", "", {"hip_back_point"}, lm("hip_back_point"), "hip level above the floor");
  }

  // The leg's loop on side s at a level, when it is whole there. Scraps of a cut (a
  // toe, a fold of fill) are no leg: at least 6 % of the height round. A leg cut in
  // pieces (a slit a scan can leave behind the ankle splits the heel from the rest)
  // is no level to measure at.
  const Ring* leg(const std::vector<Ring>& r, int s) const {
    const Ring* l = side_ring(r, xc_, s, false, 0.06 * h_);
    return l && parts_near(r, *l, 0.06 * h_) == 0 ? l : nullptr;
  }

  // The thigh's tape at a level below the crotch where hole filling bridges the
  // gap between the thighs (bridged_part), if it is a leg's (6 % of the height round).
  std::optional<Girth> bridged_leg(double y, int s) const {
    if (y >= crotch_y_) return std::nullopt;
    const std::vector<Ring>& r = rings(y);
    const Ring* m = midline(r, xc_);
    if (!m) return std::nullopt;
    std::optional<Girth> g = bridged_part(*m, xc_, s);
    if (!g || g->value_mm < 0.06 * h_) return std::nullopt;
    g->loops_cut = r.size();
    return g;
  }

  // The knee's level and the leg's centre there: the narrowest cut of the leg between
  // calf and thigh (the joint narrows it; 18-36 % of the height), the deepest local
  // minimum if there are several. Nothing when the leg is not followed there.
  struct Knee {
    double y = 0;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  };
  std::optional<Knee> find_knee(int s) {
    std::vector<double> ys, gs;
    std::vector<Eigen::Vector3d> cs;
    prefetch(at(0.18), at(0.36), 2);
    for (double y = at(0.18); y <= at(0.36); y += 2) {
      const std::vector<Ring>& r = rings(y);
      if (const Ring* l = leg(r, s)) ys.push_back(y), gs.push_back(l->girth), cs.push_back(l->centroid);
    }
    if (gs.size() < 10) return std::nullopt;
    size_t kk = 0;
    double deepest = kInf;
    for (size_t i = 0; i < gs.size(); ++i) {
      // A local minimum over +-10 mm.
      bool minimum = true;
      for (size_t j = i >= 5 ? i - 5 : 0; j < std::min(gs.size(), i + 6); ++j) minimum = minimum && gs[j] >= gs[i];
      if (minimum && i > 0 && i + 1 < gs.size() && gs[i] < deepest) deepest = gs[i], kk = i;
    }
    if (!(deepest < kInf)) kk = arg_extreme(gs, false);
    // The knee's profile is shallow: its lowest sample wanders with the scan's noise
    // (8-10 mm between two scans of one body). The vertex of a parabola fitted over
    // 2 % of the height either side does not.
    double ky = ys[kk];
    Eigen::Vector3d kc = cs[kk];
    if (const std::optional<double> v = parabola_vertex(ys, gs, kk, 0.02 * h_, true)) {
      ky = *v;
      size_t near = kk;
      for (size_t i = 0; i < ys.size(); ++i)
        if (std::abs(ys[i] - ky) < std::abs(ys[near] - ky)) near = i;
      kc = cs[near];
    }
    return Knee{ky, kc};
  }

  void measure_leg(int s) {
    const std::string sd = side(s);
    auto extreme = [&](double y0, double y1, bool largest, double* y_at, bool bridged = false) {
      std::vector<double> ys, gs;
      std::vector<Eigen::Vector3d> cs;
      prefetch(y0, y1, 2);
      for (double y = y0; y <= y1; y += 2) {
        const std::vector<Ring>& r = rings(y);
        if (const Ring* l = leg(r, s)) {
          ys.push_back(y), gs.push_back(l->girth), cs.push_back(l->centroid);
        } else if (const std::optional<Girth> b = bridged ? bridged_leg(y, s) : std::nullopt) {
          Eigen::Vector3d c = Eigen::Vector3d::Zero();
          for (const Eigen::Vector3d& p : b->tape) c += p;
          ys.push_back(y), gs.push_back(b->value_mm), cs.push_back(c / static_cast<double>(b->tape.size()));
        }
      }
      if (ys.empty()) return Eigen::Vector3d(xc_ + s * 0.05 * h_, *y_at, zc_);
      const size_t k = settle(gs, arg_extreme(gs, largest), 1.0);
      *y_at = ys[k];
      return cs[k];
    };
    // Thigh: the largest cut from 1.5 % of the height below the crotch (25 mm on
    // most bodies, the tailor's "an inch below the crotch") down to 5 %. Right under
    // the crotch the tape grows 1.5-2 mm per mm of height, and where the thighs
    // nearly touch a surface closes their gap a few mm early (the concave corner is
    // rounded): at 0.5 % below the crotch the thigh girths were -9.6/-9.2 mm on
    // female_average and -4.2/-4.1 on female_heavy (tiered rig), and moved up to 5 mm
    // between two scans of one body with the crotch.
    double ty = crotch_y_ - 0.02 * h_;
    const Eigen::Vector3d tc = extreme(crotch_y_ - 0.05 * h_, crotch_y_ - kThighBelowCrotch * h_, true, &ty, true);
    const std::optional<Girth> tb = leg(rings(ty), s) ? std::nullopt : bridged_leg(ty, s);
    girth("thigh_girth_" + sd, "Thigh girth (" + sd + ")", "5.3.20", tb ? StatusOr<Girth>(*tb) : level_girth(ty, tc),
          {"crotch"},
          "horizontal, the largest from 1.5 % of the height below the crotch down");
    const std::optional<Knee>& knee = knee_[s > 0 ? 0 : 1];
    if (!knee) {
      skip("knee_girth_" + sd, "no " + sd + " leg at knee height");
      return;
    }
    const double ky = knee->y;
    const Eigen::Vector3d kc = knee->centre;
    double cy = at(0.2);
    const Eigen::Vector3d cc = extreme(at(0.10), ky, true, &cy);
    {
      const std::vector<Ring>& r = rings(ky);
      const Ring* l = leg(r, s);
      landmark("knee_" + sd, {kc.x(), ky, l ? l->z_max : kc.z()});
    }
    // The knee height and the mid-thigh read the knees' mean level where they are
    // level (knee_reading_level): each knee's own level moves 1-2.5 mm RMS with the
    // skin's noise (a shallow profile's bottom), the two independently (tiered
    // male_average, two scans: +1.67 and -1.77 mm; male_heavy +3.22 and -0.22).
    const std::optional<Knee>& other = knee_[s > 0 ? 1 : 0];
    const double kr = knee_reading_level(ky, other ? std::optional<double>(other->y) : std::nullopt);
    const bool level_knees = other && std::abs(other->y - ky) <= kLevelKneesMm;
    {
      const Eigen::Vector3d p = lm("knee_" + sd);
      std::vector<std::string> knees = {"knee_" + sd};
      if (level_knees) knees.push_back("knee_" + side(-s));
      height("knee_height_" + sd, "Knee height (" + sd + ")", "", std::move(knees), {p.x(), kr, p.z()},
             level_knees ? "the knees' mean level above the floor (standing, they lie within 10 mm)"
                         : "knee level above the floor");
    }
    girth("knee_girth_" + sd, "Knee girth (" + sd + ")", "5.3.22", level_girth(ky, kc), {"knee_" + sd},
          "horizontal, the narrowest cut of the leg between calf and thigh (18-36 % of the height)");
    // Mid-thigh: halfway between the crotch and the knee's reading level.
    const double my = 0.5 * (crotch_y_ + kr);
    const std::vector<Ring>& mr = rings(my);
    const Ring* ml = leg(mr, s);
    std::vector<std::string> mid_landmarks = {"crotch", "knee_" + sd};
    if (level_knees) mid_landmarks.push_back("knee_" + side(-s));
    girth("mid_thigh_girth_" + sd, "Mid-thigh girth (" + sd + ")", "5.3.21",
          ml ? level_girth(my, ml->centroid) : StatusOr<Girth>(not_found("no leg at mid-thigh")), mid_landmarks,
          level_knees ? "horizontal, halfway between crotch and the knees' mean level"
                      : "horizontal, halfway between crotch and kneecap");
    girth("calf_girth_" + sd, "Calf girth (" + sd + ")", "5.3.24", level_girth(cy, cc), {"knee_" + sd},
          "horizontal, the largest between ankle and knee");
    double ay = at(0.06);
    const Eigen::Vector3d ac = extreme(at(0.04), cy, false, &ay);
    girth("min_leg_girth_" + sd, "Minimum leg girth (" + sd + ")", "5.3.25", level_girth(ay, ac), {},
          "horizontal, the smallest between ankle and calf");
  }

  void measure_arm(int s) {
    const std::string sd = side(s);
    const double ya = arm_apart_y_[s > 0 ? 0 : 1];
    std::vector<Eigen::Vector3d> c;  // centroids, armpit downwards
    std::vector<double> g;
    prefetch(ya - 3, crotch_y_ - 0.05 * h_, -3);  // where a hanging arm ends
    for (double y = ya - 3; y > floor_; y -= 3) {
      const std::vector<Ring>& r = rings(y);
      const Ring* a = side_ring(r, xc_, s, true);
      // Past the crotch the leg is on this side too: stop when the arm is gone, or
      // splits into fingers.
      if (!a || (y < crotch_y_ && std::abs(a->centroid.x() - xc_) < 0.1 * h_)) break;
      if (parts_near(r, *a, 0.06 * h_) > 0) break;
      if (!g.empty() && a->girth < 0.4 * *std::max_element(g.begin(), g.end())) break;
      c.push_back(a->centroid);
      g.push_back(a->girth);
    }
    if (c.size() < 30) {
      skip("upper_arm_girth_" + sd, "the " + sd + " arm is too short to follow");
      return;
    }
    // Wrist: the narrowest cut in the lower part of the arm, above the palm.
    const size_t w = settle(g, wrist_cut(g, 0.006 * h_), 1.0);
    // Elbow: where the axis bends (two lines fitted to the centroids, wrist to armpit).
    size_t e = w / 2;
    double best = kInf;
    for (size_t k = w / 5; k < w * 4 / 5; ++k) {
      double r1 = 0, r2 = 0;
      fit_line(c, 0, k + 1, &r1);
      fit_line(c, k, w + 1, &r2);
      if (r1 + r2 < best) best = r1 + r2, e = k;
    }
    const auto [uc, ud] = fit_line(c, 0, e + 1);
    const auto [fc, fd] = fit_line(c, e, w + 1);
    out_->posture.arm_abduction_deg[s > 0 ? 0 : 1] = std::acos(std::clamp(ud.y(), -1.0, 1.0)) * 180 / M_PI;
    out_->posture.elbow_bend_deg[s > 0 ? 0 : 1] = std::acos(std::min(1.0, std::abs(ud.dot(fd)))) * 180 / M_PI;
    auto on_axis = [](const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& p) {
      return (o + (p - o).dot(d) * d).eval();
    };
    // The elbow's centre: where the upper arm's axis passes closest to the forearm's.
    // The bend's sample c[e] moves in the 3 mm steps of the cuts, and with the
    // armpit's level, where they start; where two lines meet moves with the skin.
    // Under smooth skin noise (measure_benchmark --noise-study) the elbow point moved
    // 1.7-4.1 mm RMS on the female bodies with c[e], now 0.8-1.6 (female_heavy's
    // with its wrist's cut held, wrist_cut). An arm nearly straight has no meeting
    // point to speak of: there c[e] stands.
    Eigen::Vector3d elbow_c = on_axis(uc, ud, c[e]);
    if (const double cross = 1 - std::pow(ud.dot(fd), 2); cross > std::pow(std::sin(kMinElbowBend), 2)) {
      const Eigen::Vector3d w0 = uc - fc;
      const Eigen::Vector3d meet = uc + (ud.dot(fd) * fd.dot(w0) - ud.dot(w0)) / cross * ud;
      if ((meet - elbow_c).norm() < 0.03 * h_) elbow_c = meet;
    }
    Eigen::Vector3d wrist_c = on_axis(fc, fd, c[w]);
    // Outward: across the arm, in the frontal plane, away from the body.
    auto outward = [&](const Eigen::Vector3d& d) {
      Eigen::Vector3d o = -Eigen::Vector3d::UnitZ().cross(d);
      if (s * o.x() < 0) o = -o;
      return o.normalized().eval();
    };
    // The cut's outer point: where the ray from its centre straight out leaves it.
    // Until session 24 it was the middle of the cut's flat outer side
    // (middle_of_extreme), which slides round a limb's round side with the skin's
    // noise: under a quarter of a millimetre (measure_benchmark --noise-study) an
    // elbow's outer point moved up to 5.7 mm round the arm, and the outer arm length
    // up to 4 mm with it (male_average: the elbow 3.7 mm RMS front to back, now 0.3;
    // the outer arm length 2.7 mm RMS, now 1.6-2.0). The ray's crossing moves as far
    // as the skin does. The flat side's middle stays for a cut the ray misses.
    auto outer_point = [&](const Girth& gg, const Eigen::Vector3d& axis, const Eigen::Vector3d& out) {
      const Eigen::Vector3d across = axis.cross(out).normalized();
      if (std::optional<Eigen::Vector3d> p = ray_exit(gg.loop, loop_centre(gg.loop), out, across)) return *p;
      return middle_of_extreme(gg.loop, out, across, kFlatBand);
    };
    // The wrist itself: the narrowest cut perpendicular to the forearm within 3 % of
    // the height either side of the horizontal cuts' narrowest (which an inclined
    // forearm blurs), in the middle of its flat minimum.
    StatusOr<Girth> wg = not_found("no loop round the wrist");
    {
      const std::vector<uint32_t> wt = triangles_near(wrist_c, 0.07 * h_);
      std::vector<double> gs;
      std::vector<Girth> cuts;
      std::vector<double> ts;  // the cuts' offsets along the forearm from wrist_c
      for (double t = -0.03 * h_; t <= 0.03 * h_; t += 4) {
        const Eigen::Vector3d p = wrist_c + t * fd;
        StatusOr<Girth> g = mesh_girth(mesh_, Plane{p, fd}, p, &wt);
        if (!g.ok() || !winds_round(g->loop, p, fd) || g->value_mm > 0.25 * h_) continue;
        gs.push_back(g->value_mm);
        cuts.push_back(std::move(*g));
        ts.push_back(t);
      }
      if (!gs.empty()) {
        // Along the forearm the tape is flat over 10-20 mm at its narrowest, and
        // 1-2 mm of difference in the skin moved the narrowest cut (or the middle of
        // the cuts within 1 mm of it) 4-5 mm along the arm between two scans of one
        // body, and the outer arm length with it. Halfway between where the tape
        // has grown by 3 mm either side, on the hand's steep rise and the forearm's
        // slope, it moved about half as far; but the forearm's side rises only
        // 0.25-0.4 mm per mm, and there a quarter of a millimetre of smooth skin
        // noise moved the crossing a few mm (outer arm length 1.2-3.1 mm RMS over
        // six bodies). Since session 25 it is the vertex of a parabola whose weights
        // fall to zero kWristHalf of the height either side of the vertex itself
        // (settled_vertex: 0.5-2.6 mm RMS); the middle of the flat minimum where
        // that fit fails.
        const size_t low = arg_extreme(gs, false);
        std::optional<double> t = settled_vertex(ts, gs, low, kWristHalf * h_, true);
        if (!t) t = flat_bottom_middle(ts, gs, low, kFlatRiseMm);
        // The hand's side is steep (the tape grows 0.5-1 mm per mm into the palm), and
        // a level read there stands where a bottom's vertex moves: since session 26
        // the wrist is kWristBeforeFlare of the height back from where the tape, cut
        // by cut toward the hand, has grown kWristFlareMm over the narrowest cut
        // (past the window's end if need be). Under smooth skin noise of 0.25 mm RMS
        // the vertex left male_muscular's right wrist up to 4.3 mm along the arm
        // (outer arm length 2.42 mm RMS, largest 5.1); from the hand's flare, 0.75
        // (largest 1.1). The vertex stands where no flare is reached.
        {
          const double hand = (c[w] - c[e]).dot(fd) > 0 ? 1 : -1;
          const double flare = gs[low] + kWristFlareMm;
          std::vector<double> ht, hg;  // from the narrowest cut toward the hand
          for (size_t i = low;; i = hand > 0 ? i + 1 : i - 1) {
            ht.push_back(ts[i]), hg.push_back(gs[i]);
            if (hand > 0 ? i + 1 >= ts.size() : i == 0) break;
          }
          for (double tt = ht.back() + hand * 4; std::abs(tt) <= 0.055 * h_ && hg.back() < flare; tt += hand * 4) {
            const Eigen::Vector3d p = wrist_c + tt * fd;
            StatusOr<Girth> g = mesh_girth(mesh_, Plane{p, fd}, p, &wt);
            if (!g.ok() || !winds_round(g->loop, p, fd) || g->value_mm > 0.25 * h_) continue;
            ht.push_back(tt), hg.push_back(g->value_mm);
          }
          for (size_t i = 0; i + 1 < ht.size(); ++i)
            if (hg[i + 1] >= flare) {
              t = ht[i] + (flare - hg[i]) / (hg[i + 1] - hg[i]) * (ht[i + 1] - ht[i]) - hand * kWristBeforeFlare * h_;
              break;
            }
        }
        if (t) {
          const Eigen::Vector3d p = wrist_c + *t * fd;
          StatusOr<Girth> mid = mesh_girth(mesh_, Plane{p, fd}, p, &wt);
          if (mid.ok() && winds_round(mid->loop, p, fd) && mid->value_mm <= 0.25 * h_) {
            wrist_c = p;
            wg = std::move(mid);
          } else {
            t.reset();
          }
        }
        if (!t) {
          const size_t k = settle(gs, arg_extreme(gs, false), 1.0);
          wrist_c += ts[k] * fd;
          wg = std::move(cuts[k]);
        }
      }
    }
    const std::vector<uint32_t> et = triangles_near(elbow_c, 0.08 * h_);
    StatusOr<Girth> eg = mesh_girth(mesh_, Plane{elbow_c, ud}, elbow_c, &et);
    const Eigen::Vector3d wrist_p = wg.ok() && !wg->loop.empty() ? outer_point(*wg, fd, outward(fd)) : wrist_c;
    const Eigen::Vector3d elbow_p = eg.ok() && !eg->loop.empty() ? outer_point(*eg, ud, outward(ud)) : elbow_c;
    landmark("wrist_point_" + sd, wrist_p);
    landmark("elbow_point_" + sd, elbow_p);
    girth("wrist_girth_" + sd, "Wrist girth (" + sd + ")", "5.3.19", wg, {"wrist_point_" + sd},
          "the narrowest cut above the hand, perpendicular to the forearm's axis");
    const Eigen::Vector3d acr = lm("shoulder_point_" + sd);
    const Eigen::Vector3d mid = on_axis(uc, ud, 0.5 * (acr + elbow_c));
    // Close to the armpit the cut can reach the chest: then slide it toward the
    // elbow until its loop is the arm's alone (winds round the axis, and reaches no
    // farther than 5 % of the height from its own centre).
    // Every cut's triangles (within reach of its point) come from one search round
    // the whole slide rather than one pass over the mesh per cut.
    const double cut_radius = 0.07 * h_, slide = 0.08 * h_;
    const std::vector<uint32_t> slide_tris = triangles_near(mid, cut_radius + slide);
    StatusOr<Girth> ug = not_found("the cut never clears the chest");
    for (double off = 0; off <= slide; off += 4) {
      const Eigen::Vector3d p = mid - off * ud;
      // Cut within reach of the axis only: a loop running out of it is open, so
      // the chest never joins.
      const std::vector<uint32_t> near_p = triangles_near(p, cut_radius, slide_tris);
      StatusOr<Girth> g = mesh_girth(mesh_, Plane{p, ud}, p, &near_p);
      if (!g.ok() || !winds_round(g->loop, p, ud)) continue;
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      for (const Eigen::Vector3d& q : g->loop) centre += q;
      centre /= static_cast<double>(g->loop.size());
      double reach = 0;
      for (const Eigen::Vector3d& q : g->loop) reach = std::max(reach, (q - centre).norm());
      if (reach < 0.05 * h_) {
        ug = std::move(g);
        break;
      }
    }
    girth("upper_arm_girth_" + sd, "Upper-arm girth (" + sd + ")", "5.3.16", ug,
          {"shoulder_point_" + sd, "elbow_point_" + sd},
          "perpendicular to the upper arm's axis, halfway between shoulder point and elbow (moved toward the "
          "elbow until the cut clears the chest)");
    // Outer arm length: shoulder point, elbow, wrist along the arm's outer side.
    surface("outer_arm_length_" + sd, "Outer arm length (" + sd + ")", "5.7.8",
            {acr, elbow_p, wrist_p}, {"shoulder_point_" + sd, "elbow_point_" + sd, "wrist_point_" + sd},
            "over the skin from the shoulder point by the elbow's outer side to the wrist");
  }

  void surface(const std::string& name, const std::string& label, const std::string& clause,
               const std::vector<Eigen::Vector3d>& via, std::vector<std::string> landmarks,
               const std::string& definition) {
    BodyMeasurement m;
    m.name = name, m.label = label, m.iso_clause = clause, m.kind = "surface_length";
    for (size_t i = 0; i + 1 < via.size(); ++i) {
      if (paths_ready_.valid()) paths_ready_.get();
      StatusOr<SurfacePath> p = paths_->shortest(via[i], via[i + 1]);
      if (!p.ok()) {
        skip(name, p.status().message());
        return;
      }
      m.value_mm += p->value_mm;
      m.min_confidence = std::min(m.min_confidence, p->min_confidence);
      m.path.insert(m.path.end(), p->path.begin() + (m.path.empty() ? 0 : 1), p->path.end());
    }
    m.landmarks = std::move(landmarks);
    m.definition = definition;
    add(std::move(m));
  }

  void measure_lengths() {
    const Eigen::Vector3d l = lm("shoulder_point_left"), r = lm("shoulder_point_right"), b = lm("back_neck_point");
    surface("shoulder_width", "Across-back shoulder width", "5.4.3", {r, b, l},
            {"shoulder_point_right", "back_neck_point", "shoulder_point_left"},
            "over the skin from shoulder point to shoulder point by the back neck point");
    BodyMeasurement m;
    m.name = "biacromial_breadth", m.label = "Shoulder breadth (straight)", m.kind = "distance";
    m.value_mm = (l - r).norm();
    m.path = {r, l};
    m.landmarks = {"shoulder_point_right", "shoulder_point_left"};
    m.definition = "straight line between the shoulder points";
    add(std::move(m));
    surface("back_neck_to_waist", "Back neck point to waist", "5.4.5", {b, lm("waist_back_point")},
            {"back_neck_point", "waist_back_point"}, "over the skin down the centre back to the waist level");
  }

  const TriangleMesh& mesh_;
  const BodyMeasureOptions& opt_;
  BodyMeasurements* out_;
  std::optional<BodySlicer> slicer_;
  std::optional<SurfacePaths> paths_;
  // paths_ is being made: waited for before its first use, or (this future is
  // destroyed before paths_, and an async future waits) at the latest on leaving.
  std::future<void> paths_ready_;
  mutable std::unordered_map<int64_t, std::vector<Ring>> ring_cache_;
  Eigen::Vector3d top_ = Eigen::Vector3d::Zero(), neck_c_ = Eigen::Vector3d::Zero();
  double floor_ = 0, h_ = 0, xc_ = 0, zc_ = 0;
  double vault_y_[2] = {0, 0};  // where each armpit's join is kJoinDepth deep (the chest is cut below)
  std::optional<Knee> knee_[2];  // left, right
  double crotch_y_ = 0, armpit_y_[2] = {0, 0}, neck_y_ = 0, neck_r_ = 0, neck_tilt_ = 0;
  double arm_apart_y_[2] = {0, 0};  // where each arm's own loop ends (the armpit below a filled bridge)
  double bust_y_ = 0, underbust_y_ = 0, waist_y_ = 0, hip_y_ = 0;
  bool underbust_fold_ = false;  // the front turns in below the bust
  double breast_ = 0;  // how far that fold is a breast's crease: 0 (kChestFoldMm deep) to 1 (kBreastFoldMm)
  double bust_girth_y_ = 0;       // the bust girth's level: the fullest over a breast, else bust_y_
};

}  // namespace

double knee_reading_level(double own_y, std::optional<double> other_y) {
  return other_y && std::abs(*other_y - own_y) <= kLevelKneesMm ? 0.5 * (own_y + *other_y) : own_y;
}

double breast_reach(double fold_depth_mm) {
  return std::clamp((fold_depth_mm - kChestFoldMm) / (kBreastFoldMm - kChestFoldMm), 0.0, 1.0);
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
    w = static_cast<size_t>(std::min_element(g.begin() + static_cast<std::ptrdiff_t>(from),
                                             g.begin() + static_cast<std::ptrdiff_t>(palm)) -
                            g.begin());
  // A heavy forearm narrows twice above the hand, 25-30 mm apart and within 1-2 mm
  // of each other: the narrowest flipped between them with the skin's noise
  // (female_heavy), and the forearm's axis, fitted down to it, with it, moving the
  // elbow up to 17 mm. A second narrow nearer the hand, past a rise of more than
  // kSecondNarrowMm and within that of the first, before the palm, is the wrist.
  size_t second = w;
  bool rose = false;
  for (size_t k = w + 1; k + 3 < n && g[k] - g[w] <= palm_rise; ++k) {
    rose = rose || g[k] - g[w] > kSecondNarrowMm;
    if (rose && g[k] - g[w] <= kSecondNarrowMm && (second == w || g[k] < g[second])) second = k;
  }
  return second;
}

std::optional<Girth> bridged_part(const Ring& ring, double xc, int side) {
  const size_t n = ring.points.size();
  if (n < 3 || ring.confidence.size() != n || ring.crossing_confidence(xc) >= kMeasuredConfidence) return std::nullopt;
  const double y = ring.points.front().y();
  Girth g;
  g.plane = Plane{Eigen::Vector3d(0, y, 0), Eigen::Vector3d::UnitY()};
  g.loops_cut = 1;
  std::vector<Eigen::Vector2d> flat;
  auto kept = [&](size_t i) { return side * (ring.points[i].x() - xc) > 0 && ring.confidence[i] >= kMeasuredConfidence; };
  for (size_t i = 0; i < n; ++i) {
    if (side * (ring.points[i].x() - xc) <= 0) continue;
    g.min_confidence = std::min(g.min_confidence, ring.confidence[i]);
    if (!kept(i)) continue;
    if (kept((i + 1) % n)) g.loop_length_mm += (ring.points[(i + 1) % n] - ring.points[i]).norm();
    g.loop.push_back(ring.points[i]);
    flat.emplace_back(ring.points[i].x(), ring.points[i].z());
  }
  const std::vector<Eigen::Vector2d> hull = convex_hull(std::move(flat));
  if (hull.size() < 3) return std::nullopt;
  g.value_mm = closed_length(hull);
  for (const Eigen::Vector2d& q : hull) g.tape.emplace_back(q.x(), y, q.y());
  return g;
}

StatusOr<BodyMeasurements> measure_body(const TriangleMesh& mesh, const BodyMeasureOptions& options) {
  BodyFrameOptions frame_options;
  frame_options.floor_y = options.floor_y;
  ASSIGN_OR_RETURN(const BodyFrame frame, find_body_frame(mesh, frame_options));
  // The rules read the body facing +Z, its left at +X, standing on Y = 0.
  const TriangleMesh body = transformed(mesh, frame.body_from_world());
  BodyMeasureOptions in_body = options;
  in_body.floor_y = 0;
  BodyMeasurements out;
  Finder finder(body, in_body, &out);
  RETURN_IF_ERROR(finder.run());
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
