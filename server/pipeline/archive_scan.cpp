#include "server/pipeline/archive_scan.hpp"

#include "recon/io/atomic_file.hpp"
#include "server/pipeline/measurements_json.hpp"

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
  if (!result.surface_error.empty()) out.note = "surface failed: " + result.surface_error;
  else if (!result.measure_error.empty()) out.note = "no automatic measurements: " + result.measure_error;
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
  const nlohmann::json record = nlohmann::json::parse(record_text, nullptr, false);
  if (record.is_discarded()) return invalid_argument("scan " + scan_id + ": its raw record is not JSON");
  ASSIGN_OR_RETURN(ScanJobResult result, reprocess_scan(record, stripes, options));
  ASSIGN_OR_RETURN(storage::ScanResults results, to_results(result, options));
  return archive.add_version(scan_id, results, actor);
}

}  // namespace bodyscan::pipeline
