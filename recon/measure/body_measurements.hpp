// The automatic measurement set: landmarks found on the body's shape, then the core
// ISO 8559-1:2017 measurements taken from them, each with the geometry a person
// needs to check it (the tape's loop, the path on the skin, the plane, the
// landmarks) and a flag where it crosses surface the scan did not see.
//
// The body stands on the floor, Y up, anywhere and facing any way: the rules are
// applied in its own frame (body_frame.hpp), facing +Z with its left side at +X,
// and everything is given back in the mesh's frame. Arms held away from the sides
// and feet apart (the scanning pose, thesis §2.3; body_posture.hpp checks it).
// Landmarks come from horizontal cuts (BodySlicer) and are geometric stand-ins for
// the anatomical ones ISO 8559-1 §3 palpates. The rules live by body region in
// recon/measure/rules/ (trunk, neck and shoulders, legs, arms); docs/measurements.md
// gives each:
//   crotch        the lowest level where one loop spans the body's midline;
//   armpits       the highest level where that side's arm is still its own loop;
//   neck          the level of the smallest loop between the armpits and the head;
//   side neck     where the neck's side turns into the shoulder's top (the corner
//                 of the loop's half-width against height);
//   shoulder      where the shoulder's top turns down into the arm (the corner of
//                 the top outline seen from the front);
//   back neck     the centre back at the side neck points' level;
//   front neck    the deepest point of the front midline between neck and chest;
//   bust          the most forward point of the chest; under-bust: the deepest
//                 point of the front below it;
//   waist         the smallest torso girth between hip and under-bust;
//   hip           the level of the buttocks' greatest backward projection;
//   knee          the kneecap's forward bump above the leg's trend;
//   wrist, elbow  the arm's narrowest cut near the hand, and the bend of its axis.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "core/status.hpp"
#include "recon/geometry/triangle_mesh.hpp"
#include "recon/measure/body_frame.hpp"
#include "recon/measure/body_posture.hpp"
#include "recon/measure/body_slicer.hpp"
#include "recon/measure/fill_bound.hpp"
#include "recon/measure/girth.hpp"
#include "recon/measure/plane_section.hpp"
#include "recon/measure/profile.hpp"

namespace bodyscan {

inline constexpr const char* kBodyMeasurementsAlgorithm = "iso8559-auto-16";

struct BodyLandmark {
  std::string name;                                    // e.g. "crotch", "armpit_left", "back_neck_point"
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // mm, on (or in) the body
  // The mesh's confidence at its nearest vertex (1: measured, 0: invented by hole
  // filling); the measurements built on it inherit the lowest.
  float confidence = 1;
};

struct BodyMeasurement {
  std::string name;        // snake_case id, e.g. "waist_girth", "thigh_girth_left"
  std::string label;       // for people, e.g. "Waist girth"
  std::string iso_clause;  // ISO 8559-1:2017 clause, "" where the standard has none we could confirm
  std::string kind;        // "height", "girth", "surface_length", "distance"
  double value_mm = 0;
  // What to draw: a girth's tape (closed) and the loop it goes around, a surface
  // length's path, a height's vertical from the floor.
  std::vector<Eigen::Vector3d> path;
  bool closed = false;
  std::vector<Eigen::Vector3d> loop;   // girths: the section loop round the skin
  std::optional<Plane> plane;          // girths
  std::vector<std::string> landmarks;  // names used
  std::string definition;              // how it was taken, one sentence
  float min_confidence = 1;            // lowest mesh confidence along it and at its landmarks
  bool crosses_filled_hole() const { return min_confidence < kMeasuredConfidence; }
  // How far the skin the cameras did not see could move the value, mm
  // (fill_bound.hpp); nullopt where that is not known.
  std::optional<double> fill_bound_mm = 0.0;
  // An estimate: filled skin could move it by more than kEstimateThresholdMm, or
  // by an amount not known.
  bool estimated() const { return crosses_filled_hole() && (!fill_bound_mm || *fill_bound_mm > kEstimateThresholdMm); }
  // What its definition assumes of the posture ("" nothing), and whether the body
  // stood outside that (body_posture.hpp): then the value is not the standard's.
  std::string posture_assumed;
  bool outside_posture = false;
};

struct BodyMeasureOptions {
  // The floor's height (mm). Default: the mesh's lowest point.
  std::optional<double> floor_y;
  double step_mm = 2.0;  // spacing of the horizontal cuts the landmarks are read from
};

struct BodyMeasurements {
  double floor_y = 0;
  // Where the body stood and which way it faced: the rules were applied in this
  // frame, and everything below is given back in the mesh's (world) frame.
  BodyFrame frame;
  // How the body stood, and each part of that checked against the scanning
  // posture the rules assume.
  BodyPosture posture;
  std::vector<PostureCheck> posture_checks;
  std::vector<BodyLandmark> landmarks;
  std::vector<BodyMeasurement> measurements;
  // Measurements that could not be taken, and why.
  std::vector<std::string> skipped;
  const BodyMeasurement* find(const std::string& name) const;
  const BodyLandmark* landmark(const std::string& name) const;
};

// How far ISO 20685-1 lets a scan-derived value of the automatic set lie from the
// same value measured by hand, mm: 9 for the torso's girths, 4 for the other
// girths, the heights and the breadths (a name ending "_breadth"), 5 for lengths
// and other distances. The benchmarks and the validation against tape
// (pipeline/tape_validation.hpp) judge the set by it.
double iso20685_allowance_mm(const BodyMeasurement& m);

// Errors when the mesh is empty or the body's main parts (legs, torso, arms, neck)
// cannot be told apart; single measurements that fail are listed in `skipped`.
StatusOr<BodyMeasurements> measure_body(const TriangleMesh& mesh, const BodyMeasureOptions& options = {});

}  // namespace bodyscan
