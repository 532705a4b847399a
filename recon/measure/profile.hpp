// The 1-D profile toolkit the landmark rules read levels with: a quantity (a
// girth, a depth, a width) sampled along a walk (x, mm) and the stable stand-ins
// for its extremes and corners. The arg-min of a flat, noisy profile wanders from
// sample to sample; these move smoothly as the profile does.
//
// Every profile is given as x (monotonic) and v of the same length, k an index
// into them.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <optional>
#include <utility>
#include <vector>

namespace bodyscan {

// The boundary between lo (pred false) and hi (pred true), to `tol`.
double bisect(double lo, double hi, const std::function<bool(double)>& pred, double tol = 0.25);

// Where a sampled profile's extreme is, made stable where the profile is flat (a
// heavy waist, a wrist): the middle of the run of samples round sample k within
// `tol` of it. The arg-min of a flat profile wanders with the scan's noise; the
// middle of the flat run does not.
size_t settle(const std::vector<double>& v, size_t k, double tol);

// A flat minimum of v over x (x ascending) at v[k]: where v first rises `rise`
// above v[k] on either side (interpolated between samples), (lower x, upper x).
// Nothing when either side never rises that far.
std::optional<std::pair<double, double>> flat_bottom_span(const std::vector<double>& x, const std::vector<double>& v,
                                                          size_t k, double rise);

// The middle of that flat minimum: halfway between the two rises.
std::optional<double> flat_bottom_middle(const std::vector<double>& x, const std::vector<double>& v, size_t k,
                                         double rise);

// The parabola a t^2 + b t + c in t = x - centre least-squares fitted to the samples
// (x[i], v[i]) within `half` of `centre`: its coefficients (a, b, c), and how many
// samples it rests on. Each sample weighs 1, or with `biweight` (1 - (t/half)^2)^2,
// which reaches zero at `half`.
struct LocalParabola {
  Eigen::Vector3d coef = Eigen::Vector3d::Zero();
  int samples = 0;
};
LocalParabola local_parabola(const std::vector<double>& x, const std::vector<double>& v, double centre, double half,
                             bool biweight);

// The vertex of the parabola least-squares fitted to the samples (x[i], v[i]) within
// `half` of x[k]: where a shallow, noisy profile bottoms out (`lowest`) or tops out.
// Nothing when fewer than 7 samples lie there, the fit opens the other way (or is
// flat), or its vertex falls outside the window.
std::optional<double> parabola_vertex(const std::vector<double>& x, const std::vector<double>& v, size_t k, double half,
                                      bool lowest);

// The index of v's largest (or smallest) sample, the first of equals.
size_t arg_extreme(const std::vector<double>& v, bool largest);

// A notch in a front profile sampled as (y, z) from top to bottom (the front neck
// point, the fold under the bust): the sample lying farthest behind (at smaller Z
// than) the chord joining the profile's ends, which count at depth 0; its depth
// (<= 0, mm); and the vertex of a parabola fitted to the depths over `half` of y
// either side (parabola_vertex), where the fit finds one.
struct Notch {
  size_t k = 0;
  double depth = 0;
  std::optional<double> vertex_y;
  std::vector<double> ys, depths;  // the profile's levels and their depths
};
Notch deepest_behind_chord(const std::vector<Eigen::Vector2d>& c, double half);

// The corner of a smooth curve sampled as (x[i], v[i]) and walked until v passed
// `v_end`: the sample farthest from the chord from the first sample to where v
// reaches v_end (interpolated between the last two: the last sample jumps with the
// walk's step, and the chord's end with it), refined to the vertex of a parabola
// fitted to that distance with weights reaching zero `half` of x either side of the
// vertex (settled_vertex). Only samples on the
// chord's left (above an outline) count. Returns the sample and the refined x; the
// sample is 0 where nothing lies on that side.
std::pair<size_t, double> refined_corner(const std::vector<double>& x, const std::vector<double>& v, double v_end,
                                         double half);

// The centre of a dip in a profile v sampled over x (x monotonic), around its lowest
// sample k: the centroid of the area between v, taken as linear between samples,
// and the level v[k] + depth, over the stretch round k that stays below that level
// (a side that never rises to it ends at the last sample). Unlike the lowest sample
// or the middle of the samples near it, it moves smoothly as the profile does,
// which a flat bottom's noise otherwise carries from sample to sample. The waist's
// level (measure_body).
double minimum_centroid(const std::vector<double>& x, const std::vector<double>& v, size_t k, double depth);

// Where a shallow, noisy profile v sampled over x (x monotonic) bottoms out
// (`lowest`) or tops out, starting from its extreme sample k: the vertex of a
// parabola fitted with weights that fall smoothly to zero `half` either side of the
// vertex itself (a biweight), found by moving the window's centre to the vertex
// until it stays. A window centred on the extreme sample moves with that sample,
// which jumps with a scan's noise, and samples enter and leave it whole; this
// vertex moves smoothly with the profile. Nothing when a fit has fewer than 7
// samples, opens the other way, or leaves the samples' range. The shoulder's
// corner, the wrist along the forearm and the hip's level (measure_body).
std::optional<double> settled_vertex(const std::vector<double>& x, const std::vector<double>& v, size_t k, double half,
                                     bool lowest);

// The level (x) of a flat top of the profile v over x (x ascending): where v falls
// `drop` below its largest on both sides, over more than `min_span` of x, the vertex
// of a parabola whose weights reach zero half that span either side of itself
// (settled_vertex), fitted over the whole top. Nothing where the top is narrower,
// or does not fall that far on both sides (a chest rising into the armpits).
std::optional<double> flat_top_vertex(const std::vector<double>& x, const std::vector<double>& v, double drop,
                                      double min_span);

// A sampled profile with each sample that stands more than `tol` off the median of
// the samples within `half` of it (fewer at the ends) replaced by that median: a
// bump or dent at most `half` samples long is gone, a smooth profile keeps every
// sample. The bust's level is read from the front's profile despiked: on a flat
// chest a stray bump a few samples tall would otherwise be the foremost point.
std::vector<double> despiked(const std::vector<double>& v, size_t half, double tol);

}  // namespace bodyscan
