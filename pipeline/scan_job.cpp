#include "pipeline/scan_job.hpp"

#include <tbb/parallel_invoke.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <optional>

#include "core/json_text.hpp"
#include "pipeline/measurements_json.hpp"
#include "pipeline/scan_recording.hpp"
#include "recon/geometry/simplify.hpp"
#include "recon/io/atomic_file.hpp"
#include "recon/io/ply.hpp"
#include "storage/formats/draco_files.hpp"

namespace bodyscan::pipeline {

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// From the cloud on: the surface, then the automatic measurements.
Status surface_and_measure(const ScanJobOptions& options, ScanJobResult* out) {
  if (out->cloud.size() < 1000) {
    return failed_precondition(
        "the scan gave " + std::to_string(out->cloud.size()) +
        " points: is someone standing in the frame, and are the lasers on? " +
        (out->scan.first_plane_error.empty() ? "" : "(first frame error: " + out->scan.first_plane_error + ")"));
  }
  if (options.reconstruct) {
    ReconstructOptions ro = with_scan_normals(options.surface, out->cloud);
    if (!ro.progress) ro.progress = options.progress;
    const auto t0 = std::chrono::steady_clock::now();
    StatusOr<ReconstructResult> r = reconstruct_surface(out->cloud, ro);
    out->surface_seconds = seconds_since(t0);
    if (r.ok()) {
      out->mesh = std::move(r->mesh);
      out->surface = r->stats;
    } else if (r.status().code() == StatusCode::kCancelled) {
      return r.status();
    } else {
      out->surface_error = r.status().message();
    }
  }
  if (options.measure && !out->mesh.triangles.empty()) {
    BodyMeasureOptions mo;
    // The floor the subject stands on: the bottom frame's tubing lies on it, its
    // light centres (world Y = 0) half a tube up.
    mo.floor_y = -0.5 * out->calibration.frame.tube;
    const auto t0 = std::chrono::steady_clock::now();
    StatusOr<BodyMeasurements> body = measure_body(out->mesh, mo);
    out->measure_seconds = seconds_since(t0);
    if (body.ok())
      out->body = std::move(*body);
    else
      out->measure_error = body.status().message();
  }
  return Status::Ok();
}
}  // namespace

StatusOr<ScanJobResult> run_scan_job(const Rig& rig, const ScanJobOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  ASSIGN_OR_RETURN(RigCalibration calibration, calibrate_rig(rig, options.calibrate, options.progress));
  const double seconds = seconds_since(t0);
  ASSIGN_OR_RETURN(ScanJobResult out, run_scan_job(rig, std::move(calibration), options));
  out.calibration_seconds = seconds;
  return out;
}

StatusOr<ScanJobResult> run_scan_job(const Rig& rig, RigCalibration calibration, const ScanJobOptions& options) {
  ScanJobResult out;
  out.calibration = std::move(calibration);
  const auto t0 = std::chrono::steady_clock::now();
  ScanOptions scan_options = options.scan;
  scan_options.view.max_view_deg =
      options.max_view_deg.value_or(rig.description ? rig.description->processing.max_view_deg : 90.0);
  ScanProcessor processor(out.calibration, scan_options);
  RETURN_IF_ERROR(acquire_scan(
      rig,
      [&](Shot&& s) {
        if (options.on_scan_shot) options.on_scan_shot(s);
        return processor.consume(std::move(s));
      },
      options.every, options.progress, out.calibration.sweep_reversed));
  if (options.record_raw) {
    out.raw_record = calibration_record(out.calibration);
    out.raw_record["scan_options"] = {{"max_view_deg", scan_options.view.max_view_deg}, {"every", options.every}};
    out.raw_stripes = processor.recording();
  }
  const auto t_finish = std::chrono::steady_clock::now();
  ASSIGN_OR_RETURN(out.cloud, processor.finish());
  out.finish_seconds = seconds_since(t_finish);
  out.scan = processor.stats();
  out.scan_seconds = seconds_since(t0);
  RETURN_IF_ERROR(surface_and_measure(options, &out));
  return out;
}

StatusOr<ScanJobResult> reprocess_scan(const nlohmann::json& record, std::string_view stripes,
                                       const ScanJobOptions& options) {
  ScanJobResult out;
  ASSIGN_OR_RETURN(out.calibration, calibration_from_record(record));
  const auto t0 = std::chrono::steady_clock::now();
  ScanOptions scan_options = options.scan;
  const nlohmann::json used = record.value("scan_options", nlohmann::json::object());
  scan_options.view.max_view_deg = options.max_view_deg.value_or(used.value("max_view_deg", 90.0));
  ScanProcessor processor(out.calibration, scan_options);
  RETURN_IF_ERROR(processor.load_recording(stripes));
  out.raw_record = record;
  out.raw_stripes = std::string(stripes);
  const auto t_finish = std::chrono::steady_clock::now();
  ASSIGN_OR_RETURN(out.cloud, processor.finish());
  out.finish_seconds = seconds_since(t_finish);
  out.scan = processor.stats();
  out.scan_seconds = seconds_since(t0);
  RETURN_IF_ERROR(surface_and_measure(options, &out));
  return out;
}

namespace {

// mesh.glb: the surface, decimated first when it exceeds display_triangles, and
// what scan.json says of it (the encoding and the two triangle counts). Nothing
// for no surface.
struct DisplayFile {
  storage::DracoEncoded glb;
  size_t surface_triangles = 0;
};
StatusOr<DisplayFile> display_file(const TriangleMesh& mesh, size_t display_triangles) {
  DisplayFile out;
  if (mesh.triangles.empty()) return out;
  out.surface_triangles = mesh.num_triangles();
  std::optional<SimplifyResult> display;
  if (mesh.num_triangles() > display_triangles) {
    SimplifyOptions so;
    so.max_triangles = display_triangles;
    so.measure_deviation = false;
    ASSIGN_OR_RETURN(display, simplify(mesh, so));
  }
  ASSIGN_OR_RETURN(out.glb, storage::encode_glb(display ? display->mesh : mesh));
  return out;
}

// points.drc and the surface as `surface` asks (empty for no surface).
struct ArchivedFiles {
  std::string points_drc, surface;
};
StatusOr<ArchivedFiles> archived_files(const ScanJobResult& r, SurfaceFile surface) {
  ArchivedFiles out;
  ASSIGN_OR_RETURN(storage::DracoEncoded drc, storage::encode_drc(r.cloud));
  out.points_drc = std::move(drc.bytes);
  if (r.mesh.triangles.empty()) return out;
  if (surface == SurfaceFile::kPly) {
    out.surface = encode_ply(r.mesh, PlyFormat::kBinaryLittleEndian);
    return out;
  }
  storage::DracoOptions keep;
  keep.max_error_mm = kArchivedMeshErrorMm;
  ASSIGN_OR_RETURN(storage::DracoEncoded mesh_drc, storage::encode_mesh_drc(r.mesh, keep));
  out.surface = std::move(mesh_drc.bytes);
  return out;
}

}  // namespace

Status read_raw_record(const std::string& scan_dir, nlohmann::json* record, std::string* stripes) {
  const std::string raw = scan_dir + "/raw/";
  StatusOr<std::string> text = read_whole_file(raw + kRawRecordFile);
  StatusOr<std::string> bytes = read_whole_file(raw + kRawStripesFile);
  if (!text.ok() || !bytes.ok()) {
    return not_found(raw + " has no raw record (" + kRawRecordFile + ", " + kRawStripesFile +
                     "); was it written by bodyscan scan?");
  }
  *record = parse_json(*text);
  if (record->is_discarded()) return invalid_argument(raw + kRawRecordFile + " is not JSON");
  *stripes = std::move(*bytes);
  return Status::Ok();
}

StatusOr<ScanFiles> scan_result_files(const ScanJobResult& r, SurfaceFile surface, size_t display_triangles) {
  ScanFiles f;
  f.results["calibration.json"] = to_json(r.calibration).dump(2);
  if (!r.raw_stripes.empty()) {
    f.raw[kRawRecordFile] = r.raw_record.dump();
    f.raw[kRawStripesFile] = r.raw_stripes;
  }
  // Two single-threaded halves side by side: the display mesh and its GLB, and the
  // archived clouds and surface.
  StatusOr<DisplayFile> shown = DisplayFile{};
  StatusOr<ArchivedFiles> archived = ArchivedFiles{};
  tbb::parallel_invoke([&] { shown = display_file(r.mesh, display_triangles); },
                       [&] { archived = archived_files(r, surface); });
  if (!archived.ok()) return archived.status();
  if (!shown.ok()) return shown.status();
  f.results["points.ply"] = encode_ply(r.cloud, PlyFormat::kBinaryLittleEndian);
  f.results["points.drc"] = std::move(archived->points_drc);
  nlohmann::json glb;
  if (!r.mesh.triangles.empty()) {
    const storage::DracoEncoded& e = shown->glb;
    glb = {{"bytes", e.bytes.size()},
           {"position_bits", e.position_bits},
           {"max_error_mm", e.max_error_mm},
           {"triangles", e.triangles},
           {"surface_triangles", shown->surface_triangles}};
    f.results[surface == SurfaceFile::kPly ? "mesh.ply" : kArchivedMeshFile] = std::move(archived->surface);
    f.results["mesh.glb"] = std::move(shown->glb.bytes);
  }
  if (r.body) {
    nlohmann::json m = measurements_document("mesh.ply", "mesh");
    add_body_measurements(*r.body, &m);
    f.results["measurements.json"] = m.dump(1);
  }
  nlohmann::json j;
  j["points"] = r.cloud.size();
  if (r.body) j["posture"] = to_json(r.body->posture, r.body->posture_checks);
  if (!glb.is_null()) j["mesh_glb"] = glb;
  j["frames"] = r.scan.frames;
  j["frames_unseen"] = r.scan.frames_unseen;
  j["frames_without_plane"] = r.scan.frames_without_plane;
  j["far_bottom_estimated"] = r.scan.far_bottom_estimated;
  j["fourth_point_rms_mm"] = r.scan.fourth_point_rms_mm;
  j["points_redundant"] = r.scan.points_redundant;
  j["points_grazing"] = r.scan.points_grazing;
  j["processing_seconds"] = r.scan.processing_seconds;
  j["lasers"] = nlohmann::json::array();
  for (const LaserSweepReport& s : r.scan.sweeps) {
    j["lasers"].push_back({{"id", r.calibration.laser_ids[static_cast<size_t>(s.laser)]},
                           {"sweep_fitted", s.fitted},
                           {"error", s.error},
                           {"pole_point_rms_mm", s.rms_mm},
                           {"pole_points_used", s.points_used},
                           {"pole_points_rejected", s.points_rejected},
                           {"degrees_per_step", s.degrees_per_step},
                           {"axis_point_mm", {s.axis_point.x(), s.axis_point.y(), s.axis_point.z()}},
                           {"axis_direction", {s.axis_direction.x(), s.axis_direction.y(), s.axis_direction.z()}}});
  }
  if (!r.scan.sway.empty()) {
    const SwayEstimate& w = r.scan.sway;
    nlohmann::json path = nlohmann::json::array();
    for (const Eigen::Vector3d& k : w.knots) path.push_back({k.x(), k.y(), k.z()});
    j["sway"] = {{"peak_mm", w.peak_mm},
                 {"pairs", w.pairs},
                 {"iterations", w.iterations},
                 {"last_move_mm", w.last_move_mm},
                 {"pair_rms_before_mm", w.rms_before_mm},
                 {"pair_rms_after_mm", w.rms_after_mm},
                 {"first_frame", w.first_frame},
                 {"knot_frames", w.knot_frames},
                 {"hold",
                  {{"still", w.regularization.still},
                   {"per_axis", w.regularization.per_axis},
                   {"ridge_scale", w.regularization.ridge_scale},
                   {"slow_scale", w.regularization.slow_scale},
                   {"held_out_rms_mm", w.held_out_rms_mm}}},
                 {"path_mm", path}};
  } else if (!r.scan.sway_not_estimated.empty()) {
    j["sway_not_estimated"] = r.scan.sway_not_estimated;
  }
  if (!r.surface_error.empty()) j["surface_error"] = r.surface_error;
  if (!r.measure_error.empty()) j["measure_error"] = r.measure_error;
  j["calibration_seconds"] = r.calibration_seconds;
  j["scan_seconds"] = r.scan_seconds;
  j["after_last_frame_seconds"] = {
      {"cloud", r.finish_seconds}, {"surface", r.surface_seconds}, {"measurements", r.measure_seconds}};
  if (!r.mesh.triangles.empty()) {
    j["mesh"] = {{"vertices", r.mesh.vertices.size()},
                 {"triangles", r.mesh.triangles.size()},
                 {"holes_filled", r.surface.holes_filled},
                 {"seconds", r.surface.total_seconds()}};
  }
  f.results["scan.json"] = j.dump(2);
  return f;
}

Status write_scan_results(const ScanJobResult& r, const std::string& dir) {
  ASSIGN_OR_RETURN(ScanFiles files, scan_result_files(r));
  const std::filesystem::path d(dir);
  std::error_code ec;
  std::filesystem::create_directories(d / "raw", ec);
  if (ec) return io_error("cannot create '" + (d / "raw").string() + "': " + ec.message());
  for (const auto& [name, bytes] : files.raw)
    RETURN_IF_ERROR(write_file_atomically((d / "raw" / name).string(), bytes));
  // scan.json last: its presence says the rest is there.
  for (const auto& [name, bytes] : files.results)
    if (name != "scan.json") RETURN_IF_ERROR(write_file_atomically((d / name).string(), bytes));
  return write_file_atomically((d / "scan.json").string(), files.results["scan.json"]);
}

}  // namespace bodyscan::pipeline
