// The whole job of `bodyscan scan` (and, later, of the server's scan button): calibrate
// the rig, scan, turn the frames into a point cloud as they come, reconstruct the
// surface, write the results.
#pragma once

#include <optional>
#include <string>

#include "recon/geometry/triangle_mesh.hpp"
#include "recon/surface/reconstruct.hpp"
#include "server/pipeline/calibrate.hpp"
#include "server/pipeline/scan.hpp"

namespace bodyscan::pipeline {

struct ScanJobOptions {
  int every = 1;  // scan every Nth laser step
  CalibrateOptions calibrate;
  ScanOptions scan;
  // Overrides the rig description's processing.max_view_deg (ScanOptions::view).
  std::optional<double> max_view_deg;
  bool reconstruct = true;
  ReconstructOptions surface;
  ProgressFn progress;  // stages: calibration..., scan, surface...
};

struct ScanJobResult {
  RigCalibration calibration;
  PointCloud cloud;
  ScanStats scan;
  TriangleMesh mesh;  // empty unless reconstructed
  ReconstructStats surface;
  double calibration_seconds = 0;  // acquisition and processing
  double scan_seconds = 0;         // acquisition and processing
};

StatusOr<ScanJobResult> run_scan_job(const Rig& rig, const ScanJobOptions& options = {});

// DIR/points.ply, DIR/mesh.ply (when reconstructed), DIR/calibration.json and
// DIR/scan.json (the figures), each written atomically. Creates DIR.
Status write_scan_results(const ScanJobResult& result, const std::string& dir);

}  // namespace bodyscan::pipeline
