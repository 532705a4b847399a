// The trunk's landmark rules and measurements: the crotch, the armpits (where each
// arm meets the trunk), the bust, under-bust, waist and hip levels, and the girths
// taken there (docs/measurements.md, "Landmarks" and "Measurements").
#pragma once

#include "core/status.hpp"
#include "recon/measure/rules/body_cuts.hpp"
#include "recon/measure/rules/sheet.hpp"

namespace bodyscan::rules {

// Where an arm meets the trunk.
struct ArmJoin {
  // The top of the first long run of cuts in which the arm is its own loop, up
  // from the hand: the arm is followed down from there.
  double followed_from_y = 0;
  // The top of the gap between arm and flank under the armpit: followed_from_y,
  // or where an arm lies against the flank, of the run above the contact.
  double apart_y = 0;
  // The armpit's level: apart_y, or above a filled bridge between arm and flank,
  // the first level where the gap's crossing is measured skin.
  double armpit_y = 0;
  // Where the join of arm and flank has grown kJoinDepth of the stature long front
  // to back: the chest is cut under it.
  double vault_y = 0;
};

// The trunk's levels, mm above the floor.
struct TrunkLevels {
  double bust_y = 0;        // the chest's most forward level (the bust points)
  double bust_girth_y = 0;  // the bust girth's: the fullest over a breast, else bust_y
  double underbust_y = 0;
  double waist_y = 0;
  double hip_y = 0;
  bool underbust_fold = false;  // the front turns in below the bust
  double breast = 0;            // breast_reach of that fold's depth
};

// The crotch: down from the trunk (55 % of the stature), the first level where no
// loop spans the midline (the legs part), raised past a filled bridge and a
// rounded corner. Records the `crotch` landmark; errors when the legs are not
// apart anywhere down to a quarter of the stature.
StatusOr<double> find_crotch(const BodyCuts& cuts, MeasurementSheet& sheet);

// Where the arm on `side` meets the trunk, up from just above the crotch. Records
// the `armpit_<side>` landmark; errors when that arm is never apart from the body.
StatusOr<ArmJoin> find_arm_join(const BodyCuts& cuts, MeasurementSheet& sheet, double crotch_y, Side side);

// The bust, under-bust, waist and hip levels. Records the bust points, the
// under-bust front point, the hip's back point and the waist's back and front
// points.
TrunkLevels find_trunk_levels(const BodyCuts& cuts, MeasurementSheet& sheet, double crotch_y,
                              const PerSide<ArmJoin>& arms);

// The chest, bust, under-bust, waist, hip and maximum hip girths, the waist and
// hip heights.
void measure_trunk(const BodyCuts& cuts, MeasurementSheet& sheet, double crotch_y, const PerSide<ArmJoin>& arms,
                   const TrunkLevels& levels);

// How far the fold under a chest, `fold_depth_mm` behind its chord, is a breast's
// crease: 0 up to 6 mm (a man's fold), 1 from 14 mm (a breast's crease), in
// proportion between. Over a breast the bust girth is the fullest within 1.2 % of
// the stature of the apex's level, times this: a small breast's girth then does
// not jump between the apex's reading and the fullest as its crease's depth moves
// with a scan's noise.
double breast_reach(double fold_depth_mm);

}  // namespace bodyscan::rules
