// The posture check before a scan: one quick, coarse sweep of the lasers (every
// Nth step), a coarse surface, and the posture read from it and checked against
// the posture the measurement rules assume (body_posture.hpp): the arms, the
// feet and the turn (the head is left to the full scan). The operator
// corrects how the customer stands before the full scan, not after it. Nothing
// is stored.
#pragma once

#include <nlohmann/json.hpp>

#include <functional>
#include <vector>

#include "pipeline/scan_job.hpp"
#include "recon/measure/body_posture.hpp"

namespace bodyscan::pipeline {

// Every 4th laser step: a quarter of the scan's frames, each laser's stripes
// about 14 mm apart on the body, dense enough that each arm is cut into loops of
// its own; at every 6th or 8th the surface joins a turned body's far arm to its
// flank and the arm is read as resting against it. docs/benchmarks.md §12, "The
// posture check".
inline constexpr int kPostureSweepEvery = 4;
// The sweep's surface at fixed 4 mm voxels: fine enough to keep a heavy body's
// arm held 20-30° apart from its flank (at 6 mm the two merge and the arm reads
// as resting against the body), and a fixed size so that a rig with many
// cameras, whose points are dense along each stripe, is not surfaced at the
// scan's own fine voxels (on the tiered rig 35 s rather than a few).
inline constexpr float kPostureSweepVoxelMm = 4.f;

struct PostureSweepOptions {
  int every = kPostureSweepEvery;
  ProgressFn progress;
  std::function<void(const Shot&)> on_scan_shot;
};

struct PostureSweep {
  BodyPosture posture;
  std::vector<PostureCheck> checks;
  bool ok = false;                 // every part found lies inside the scanning posture
  size_t frames = 0;               // camera frames taken (all cameras)
  size_t points = 0;               // in the sweep's cloud
  double acquisition_seconds = 0;  // the sweep itself (on the simulated rig: rendering)
  double processing_seconds = 0;   // cloud, surface and posture after the last frame
};

// Errors as run_scan_job does (no usable cloud, cancelled), and when no posture
// can be read from the sweep's surface (nobody standing in the rig).
StatusOr<PostureSweep> sweep_posture(const Rig& rig, RigCalibration calibration,
                                     const PostureSweepOptions& options = {});

// {"posture": to_json(posture, checks), "ok", "frames", "points", "acquisition_seconds",
// "processing_seconds"} (docs/api.md).
nlohmann::json to_json(const PostureSweep& sweep);

}  // namespace bodyscan::pipeline
