#include "pipeline/archive_scan.hpp"

#include "core/json_text.hpp"
#include "pipeline/measurements_json.hpp"
#include "recon/io/atomic_file.hpp"
#include "storage/formats/draco_files.hpp"

namespace bodyscan::pipeline {

nlohmann::json algorithm_versions(const ScanJobOptions& options) {
  return {{"planes", to_string(options.scan.planes)},
          {"triangulation", to_string(options.scan.triangulate.method)},
          {"surface", options.reconstruct ? "anisotropic-kernels-1" : "none"},
          {"hole_fairing", options.surface.hole_fairing == HoleFairing::kThinPlate ? "thin-plate" : "membrane"},
          {"measurements", options.measure && options.reconstruct ? kBodyMeasurementsAlgorithm : "none"}};
}

namespace {

StatusOr<storage::ScanResults> to_results(const ScanJobResult& result, const ScanJobOptions& options) {
  // The archive keeps the surface as Draco within 0.01 mm (docs/archive.md); the
  // served copy is mesh.glb.
  ASSIGN_OR_RETURN(ScanFiles files, scan_result_files(result, SurfaceFile::kArchiveDraco));
  storage::ScanResults out;
  out.files = std::move(files.results);
  out.algorithms = algorithm_versions(options);
  if (!result.surface_error.empty())
    out.note = "surface failed: " + result.surface_error;
  else if (!result.measure_error.empty())
    out.note = "no automatic measurements: " + result.measure_error;
  if (result.body)
    for (const BodyMeasurement& m : result.body->measurements) {
      storage::MeasurementRecord r;
      r.name = m.name, r.label = m.label, r.kind = m.kind, r.iso_clause = m.iso_clause, r.value_mm = m.value_mm;
      r.geometry = to_json(m);
      out.measurements.push_back(std::move(r));
    }
  return out;
}

}  // namespace

Status archive_scan(storage::Archive& archive, const std::string& scan_id, const ScanJobResult& result,
                    const ScanJobOptions& options) {
  ASSIGN_OR_RETURN(storage::ScanResults results, to_results(result, options));
  if (!result.raw_stripes.empty()) {
    RETURN_IF_ERROR(archive.put_raw(scan_id, kRawRecordFile, result.raw_record.dump()));
    RETURN_IF_ERROR(archive.put_raw(scan_id, kRawStripesFile, result.raw_stripes));
  }
  return archive.complete_scan(scan_id, results);
}

StatusOr<int> reprocess_archived_scan(storage::Archive& archive, const std::string& scan_id,
                                      const ScanJobOptions& options, const std::string& actor) {
  ASSIGN_OR_RETURN(std::string record_path, archive.file_path(scan_id, -1, kRawRecordFile));
  ASSIGN_OR_RETURN(std::string stripes_path, archive.file_path(scan_id, -1, kRawStripesFile));
  ASSIGN_OR_RETURN(std::string record_text, read_whole_file(record_path));
  ASSIGN_OR_RETURN(std::string stripes, read_whole_file(stripes_path));
  const nlohmann::json record = parse_json(record_text);
  if (record.is_discarded()) return invalid_argument("scan " + scan_id + ": its raw record is not JSON");
  ASSIGN_OR_RETURN(ScanJobResult result, reprocess_scan(record, stripes, options));
  ASSIGN_OR_RETURN(storage::ScanResults results, to_results(result, options));
  return archive.add_version(scan_id, results, actor);
}

StatusOr<TriangleMesh> archived_surface(const storage::Archive& archive, const std::string& scan_id, int version) {
  ASSIGN_OR_RETURN(std::string path, archive.file_path(scan_id, version, kArchivedMeshFile));
  ASSIGN_OR_RETURN(std::string bytes, read_whole_file(path));
  return storage::decode_mesh_drc(bytes);
}

StatusOr<storage::MeasurementSheet> archived_sheet(const storage::Archive& archive, const std::string& scan_id) {
  ASSIGN_OR_RETURN(storage::ScanRecord r, archive.scan(scan_id));
  ASSIGN_OR_RETURN(std::vector<storage::MeasurementRecord> ms, archive.measurements(r.id));
  storage::MeasurementSheet sheet;
  sheet.customer_ref = r.customer_id, sheet.scan_id = r.id, sheet.taken_at = r.started_at;
  sheet.operator_name = r.operator_name;
  for (const auto& m : ms) {
    storage::SheetEntry e;
    e.iso_clause = m.iso_clause, e.name = m.name, e.label = m.label.empty() ? m.name : m.label, e.kind = m.kind;
    e.value_mm = m.value_mm;
    // Scans archived before "estimated" existed flag every line over filled skin.
    e.flagged = m.geometry.value("estimated", m.geometry.value("crosses_filled_hole", false));
    e.source = m.source == "user" ? "saved by " + m.created_by : "automatic";
    if (m.geometry.contains("path") && m.geometry["path"].is_array())
      for (const auto& p : m.geometry["path"])
        if (p.is_array() && p.size() == 3 && p[0].is_number() && p[1].is_number() && p[2].is_number())
          e.path.emplace_back(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
    e.closed = m.geometry.value("closed", false);
    sheet.entries.push_back(std::move(e));
  }
  return sheet;
}

}  // namespace bodyscan::pipeline
