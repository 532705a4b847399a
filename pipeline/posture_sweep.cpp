#include "pipeline/posture_sweep.hpp"

#include <chrono>

#include "pipeline/measurements_json.hpp"

namespace bodyscan::pipeline {

StatusOr<PostureSweep> sweep_posture(const Rig& rig, RigCalibration calibration, const PostureSweepOptions& options) {
  if (options.every < 1) return invalid_argument("posture check: 'every' must be at least 1");
  ScanJobOptions o;
  o.every = options.every;
  o.progress = options.progress;
  o.on_scan_shot = options.on_scan_shot;
  o.record_raw = false;
  o.surface.voxel_size = kPostureSweepVoxelMm;
  const auto t0 = std::chrono::steady_clock::now();
  ASSIGN_OR_RETURN(ScanJobResult r, run_scan_job(rig, std::move(calibration), o));
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!r.body) {
    return failed_precondition("posture check: no body to read the posture from (" +
                               (r.surface_error.empty() ? r.measure_error : r.surface_error) +
                               "): is the customer standing in the rig?");
  }
  PostureSweep out;
  out.posture = r.body->posture;
  // The head is left to the full scan: the sweep's stripes lie too far apart on
  // the cranium, most of which the level cameras never see, for the axis of its
  // cuts (the head read 20-43 degrees forward on a level head).
  out.posture.head_tilt_deg.reset();
  out.posture.head_side_tilt_deg.reset();
  for (const PostureCheck& c : r.body->posture_checks)
    if (c.part != "head") out.checks.push_back(c);
  out.ok = true;
  for (const PostureCheck& c : out.checks) out.ok = out.ok && c.ok;
  out.frames = r.scan.frames;
  out.points = r.cloud.size();
  out.acquisition_seconds = r.scan_seconds - r.scan.processing_seconds;
  out.processing_seconds = total - out.acquisition_seconds;
  return out;
}

nlohmann::json to_json(const PostureSweep& sweep) {
  return {{"posture", to_json(sweep.posture, sweep.checks)},
          {"ok", sweep.ok},
          {"frames", sweep.frames},
          {"points", sweep.points},
          {"acquisition_seconds", sweep.acquisition_seconds},
          {"processing_seconds", sweep.processing_seconds}};
}

}  // namespace bodyscan::pipeline
