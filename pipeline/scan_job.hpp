// The whole job of `bodyscan scan` (and, later, of the server's scan button): calibrate
// the rig, scan, turn the frames into a point cloud as they come, reconstruct the
// surface, write the results.
#pragma once

#include <nlohmann/json.hpp>

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>

#include "pipeline/calibrate.hpp"
#include "pipeline/scan.hpp"
#include "recon/geometry/triangle_mesh.hpp"
#include "recon/measure/body_measurements.hpp"
#include "recon/surface/reconstruct.hpp"

namespace bodyscan::pipeline {

// A body is closed: every opening a scan leaves (the soles, the crown, the insides
// of the legs, under the arms) is a hole to fill, however large; measurements flag
// the girths that cross the fill.
inline ReconstructOptions body_surface_options() {
  ReconstructOptions o;
  o.max_hole_area_fraction = 1.0;
  // What a scan leaves unseen (crown, flanks, shoulders' tops, the insides of the
  // legs) is curved skin: a thin plate continues the curvature over it, where a
  // membrane spans it flat - the crown 9-15 mm low. Measured both ways in
  // docs/benchmarks.md §7.
  o.hole_fairing = HoleFairing::kThinPlate;
  // A body's sides are seen only at grazing angles, by sparse stripes: at 10 % of
  // the median weight the field leaves a strip open along them, ankles to head, on
  // the square rig, and on a heavy body the holes then join into loops round the
  // whole body that no fill spans well. 2 % keeps that skin, and more of the
  // automatic set falls within the ISO allowance on both shipped layouts for it
  // (docs/benchmarks.md §7).
  o.min_relative_weight = 0.02f;
  return o;
}

// The options for surfacing a scan's cloud. The view-angle step leaves quick normals
// (fixed k) in the cloud for viewers; unless told otherwise, the surface estimates its
// own, sized to the noise, and turns them to the cameras that saw each point.
inline ReconstructOptions with_scan_normals(ReconstructOptions o, const PointCloud& cloud) {
  if (o.normal_source == NormalSource::kAuto && cloud.has_cameras()) o.normal_source = NormalSource::kCameras;
  return o;
}

struct ScanJobOptions {
  int every = 1;  // scan every Nth laser step
  CalibrateOptions calibrate;
  ScanOptions scan;
  // Overrides the rig description's processing.max_view_deg (ScanOptions::view).
  std::optional<double> max_view_deg;
  bool reconstruct = true;
  ReconstructOptions surface = body_surface_options();
  bool measure = true;     // the automatic set on the surface (measure_body)
  bool record_raw = true;  // keep the raw record (scan_recording.hpp) in the result
  ProgressFn progress;     // stages: calibration..., scan, surface...
  // Sees every scan shot before it is processed (live previews); called on the
  // job's thread, so it must be quick.
  std::function<void(const Shot&)> on_scan_shot;
};

struct ScanJobResult {
  RigCalibration calibration;
  PointCloud cloud;
  ScanStats scan;
  TriangleMesh mesh;  // empty unless reconstructed
  ReconstructStats surface;
  // Why the surface could not be built (the cloud is still good and kept); empty
  // when it was, or was not asked for.
  std::string surface_error;
  std::optional<BodyMeasurements> body;  // the automatic set, when measured
  std::string measure_error;             // why it could not be (the surface is kept)
  // The raw record, to reprocess the scan later: the calibration record (with the
  // scan options used, "scan_options") and the frames' stripes, compressed.
  nlohmann::json raw_record;
  std::string raw_stripes;
  double calibration_seconds = 0;  // acquisition and processing
  double scan_seconds = 0;         // acquisition and processing, up to the finished cloud
  // What runs after the last frame, seconds: the cloud finished (sweeps merged,
  // the sway undone; the last part of scan_seconds), the surface, the automatic set.
  double finish_seconds = 0, surface_seconds = 0, measure_seconds = 0;
};

// Errors when calibration or the scan fails, or the scan gives no usable cloud; a
// failed reconstruction is reported in surface_error, the cloud kept. Cancelled
// (options.progress returned false) at any stage: a kCancelled error.
StatusOr<ScanJobResult> run_scan_job(const Rig& rig, const ScanJobOptions& options = {});
// The same against a calibration made earlier (the workstation calibrates once and
// scans many times).
StatusOr<ScanJobResult> run_scan_job(const Rig& rig, RigCalibration calibration, const ScanJobOptions& options = {});

// The scan again from its raw record: the cloud, surface and measurements as
// `options` makes them now (the scan options recorded, unless overridden).
StatusOr<ScanJobResult> reprocess_scan(const nlohmann::json& record, std::string_view stripes,
                                       const ScanJobOptions& options = {});

inline constexpr const char* kRawRecordFile = "record.json";  // in DIR/raw and the archive's raw/
inline constexpr const char* kRawStripesFile = "stripes.bin";

// The raw record a scan left in SCAN_DIR/raw (`bodyscan scan`, write_scan_results),
// ready for reprocess_scan. Errors name the directory and say whether the files are
// missing or the record is not JSON.
Status read_raw_record(const std::string& scan_dir, nlohmann::json* record, std::string* stripes);

// Every file a scan leaves, as bytes: the results (calibration.json, points.ply,
// points.drc, the surface, mesh.glb, measurements.json, scan.json, as far as the
// job got) and the raw record (record.json, stripes.bin). The surface is mesh.ply,
// or for the archive mesh.drc (Draco within 0.01 mm, a seventeenth of the size).
// The Draco files are checked by decoding them again (storage/formats/draco_files.hpp).
// mesh.glb is the screen's copy: a surface larger than `display_triangles` is
// decimated to it first (recon/geometry/simplify.hpp; kept closed). The surface
// file and the measurements are the full surface's.
enum class SurfaceFile { kPly, kArchiveDraco };
inline constexpr const char* kArchivedMeshFile = "mesh.drc";
inline constexpr double kArchivedMeshErrorMm = 0.01;
// A software renderer draws half a million triangles in about half a second
// (docs/benchmarks.md §10), and the eye sees no facets at that density on a body.
inline constexpr size_t kDisplayTriangles = 500000;
struct ScanFiles {
  std::map<std::string, std::string> results, raw;
};
StatusOr<ScanFiles> scan_result_files(const ScanJobResult& result, SurfaceFile surface = SurfaceFile::kPly,
                                      size_t display_triangles = kDisplayTriangles);

// DIR/points.ply, DIR/mesh.ply (when reconstructed), DIR/measurements.json (when
// measured; docs/measurements.md), DIR/calibration.json and DIR/scan.json (the
// figures), DIR/raw/record.json and DIR/raw/stripes.bin (the raw record, for
// `bodyscan reprocess`), each written atomically. Creates DIR.
Status write_scan_results(const ScanJobResult& result, const std::string& dir);

}  // namespace bodyscan::pipeline
