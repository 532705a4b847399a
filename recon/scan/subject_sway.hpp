// A standing person sways: a few millimetres, slowly (postural sway, mostly below
// 1 Hz, mostly horizontal). The lasers sweep one after another, so each sweep sees
// the body where it stood at that moment, and two sweeps of the same skin seconds
// apart disagree by the sway in between: every girth comes out a few millimetres
// large, the small ones (neck, wrist) the most. The thesis rig takes every point as
// it was measured (§3.1.4: no registration).
//
// Here the sway is estimated from the scan itself and undone. Each point keeps its
// frame (its moment). Where a sweep's point lies on skin another sweep saw at a
// clearly different moment, the point's height above that sweep's local surface
// (a small quadratic height field), along its normal, is the sway between the two
// moments along that normal. Over a scan that is tens of thousands of such differences, from skin that
// faces every way, and one smooth horizontal path through time - a piecewise-linear
// curve with a knot every few frames, its second differences penalised - explains
// them best (robust least squares, re-paired a few times as the sweeps come
// together). Its mean is zero: the body is put where it stood on average.
//
// What the scan cannot tell: a sway that moves every pair of overlapping moments
// alike (e.g. one sweep alone moving sideways along a flat patch), and any sway
// between moments whose sweeps see no common skin. A small weight on the sway itself
// holds those near zero, and the smoothness term carries the path across. How
// firmly (one weight for all the pairs, or per axis, where sideways sway shows
// only on skin facing sideways) is chosen per scan: the firmest hold that explains
// pairs it was not fitted to about as well as any (cross-validation by place).
// docs/scan-processing.md ("The subject's sway") has the figures.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "core/status.hpp"
#include "recon/geometry/point_cloud.hpp"

namespace bodyscan {

// How firmly the path is held: its smoothness and its size, against the pairs.
struct SwayRegularization {
  double ridge_scale = 1;  // the size's weight, times SwayOptions::ridge
  // The smoothness and the size weigh against what the pairs see along each axis
  // (their weight times the normals' squared x or z) rather than all of their
  // weight: sideways, which the pairs see only on skin facing sideways, is then held
  // less firmly, and the path follows the sideways sway within a sweep more fully.
  bool per_axis = false;
  // An extra weight (times SwayOptions::ridge) on the path's slow part, its mean
  // over SwayOptions::slow_frames. A sweep-long offset between the front and the back
  // sweeps thins or thickens the body and hardly shows in the pairs; this keeps it
  // held when the rest is let go.
  double slow_scale = 0;
  // No path at all: the body is taken to have stood still. Offered at the first
  // pairing only (made at no sway), where it competes with the moving holds on the
  // skin they were not fitted to. A still body's sweeps disagree a little
  // (grazing views, calibration), and a moving hold, however firm, turns that into
  // a path that thins the neck and waist slightly; held still, a still scan
  // stays nearer the truth (docs/benchmarks.md §7, "Repeat pairs").
  bool still = false;
};

struct SwayOptions {
  int knot_frames = 20;  // knot spacing of the sway's path, frames (1/3 s at 60 Hz)
  // Neighbourhood in which a point meets another sweep's skin: at least this, and at
  // least 2.5 stripe spacings (measured from the cloud: a scan of every Nth step has
  // its stripes N times farther apart), so that it holds two stripes of each sweep.
  float radius_mm = 8.f;
  int min_frame_gap = 30;          // moments closer than this (frames) are taken as one
  size_t max_anchors = 30000;      // points whose neighbourhoods are examined, spread over the scan
  size_t max_candidates = 500000;  // points their neighbourhoods are drawn from (an even share of a denser cloud)
  size_t min_group = 6;            // points of the other sweep needed for its local surface
  // Re-pairings, at most: each finds the pairs again where the last path put the
  // sweeps, and fits the path to them; they stop once no knot moved more than
  // converged_mm. The first pairing is at no sway, and the path comes up to the
  // sway over several; the arms' moments, seen at the sweeps' ends by few pairs,
  // come last, so a swaying body needs several more re-pairings than a still one
  // before the path settles (the counts: docs/scan-processing.md, "The subject's
  // sway").
  int iterations = 12;
  double converged_mm = 0.05;
  double smoothness = 0.01;    // weight of the path's second differences, relative to the data
  double ridge = 0.003;        // weight of the sway itself, relative: holds what the pairs cannot see near zero
  double huber_mm = 0.75;      // residuals beyond this count linearly
  double max_residual_mm = 6;  // pairs farther apart than this are not the same skin
  bool vertical = false;       // also estimate a vertical sway (off: posture moves sideways)
  // Stripes farther apart than this (a scan of every 5th step or coarser on the
  // thesis rig) leave too little overlap to tell sway from shape: not estimated.
  double max_stripe_spacing_mm = 16;
  // The candidate holds, firmest first. With two or more and cv_folds >= 2, the
  // pairs are dealt out to folds by where their skin is; each candidate's path is
  // fitted without each fold in turn and scored on that fold's pairs. The firmest
  // candidate whose score is within one standard error of the best one's is
  // taken: a looser hold must explain skin it was not fitted to clearly better. A
  // still body's sweeps disagree a little (calibration, grazing views) in ways a
  // loose path would take for sway; that disagreement is local, and does not carry
  // over to other skin, while a sway does.
  std::vector<SwayRegularization> regularizations = {
      {0, false, 0, true},  // no sway
      {1, false, 0},        // every pair's weight
      {1, true, 30},        // per axis, the slow part held
      {0.3, true, 30},      // and the size's weight a third
  };
  int cv_folds = 5;
  float cv_block_mm = 150;  // the cubes of space dealt out to the folds
  int slow_frames = 600;    // the slow part's window (10 s at 60 Hz: longer than a sway, about two sweeps)
};

struct SwayEstimate {
  int first_frame = 0;  // frame of knot 0
  int knot_frames = 1;
  std::vector<Eigen::Vector3d> knots;          // the sway at each knot, mm (mean zero)
  size_t pairs = 0;                            // point-to-sweep pairs in the last solve
  int iterations = 0;                          // re-pairings made
  double last_move_mm = 0;                     // the most any knot moved in the last one
  double radius_mm = 0;                        // the neighbourhood used
  double stripe_spacing_mm = 0;                // median distance between a sweep's neighbouring stripes
  double rms_before_mm = 0, rms_after_mm = 0;  // of those pairs' distances (robust RMS)
  double peak_mm = 0;                          // largest |sway| over the knots
  SwayRegularization regularization;           // the hold taken
  std::vector<double> held_out_rms_mm;         // each candidate's RMS over the held-out pairs (empty: no choice made)
  std::string not_estimated;                   // when empty(): why (nothing to compare, stripes too far apart)

  // The sway at `frame` (linear between knots, constant beyond the ends).
  Eigen::Vector3d at(double frame) const;
  bool empty() const { return knots.empty(); }
};

// Needs positions, frame and laser per point (confidence optional). A cloud whose
// points come from fewer than two moments far enough apart, or whose stripes lie
// too far apart, yields an empty estimate saying why, not an error.
StatusOr<SwayEstimate> estimate_sway(const PointCloud& cloud, const SwayOptions& options = {});

// Moves every point back by the sway at its frame. Points of unknown frame stay.
void undo_sway(PointCloud& cloud, const SwayEstimate& sway);

}  // namespace bodyscan
