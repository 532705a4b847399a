// A scan job's results into the archive (storage/archive): the raw record as the
// scan's raw data, every result file as version 1 (or a new version when the scan
// is reprocessed), the automatic measurements as records with their geometry.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

#include "pipeline/scan_job.hpp"
#include "storage/archive/archive.hpp"
#include "storage/formats/measurement_sheet.hpp"

namespace bodyscan::pipeline {

// The algorithms a result came from, recorded with each version.
nlohmann::json algorithm_versions(const ScanJobOptions& options);

// Completes a running scan with the job's results (raw data first).
Status archive_scan(storage::Archive& archive, const std::string& scan_id, const ScanJobResult& result,
                    const ScanJobOptions& options);
// Reprocesses an archived scan from its raw record with `options` and keeps the
// results as a new version. Returns the version.
StatusOr<int> reprocess_archived_scan(storage::Archive& archive, const std::string& scan_id,
                                      const ScanJobOptions& options, const std::string& actor);

// An archived scan's surface (mesh.drc) of a version (0: the current one).
StatusOr<TriangleMesh> archived_surface(const storage::Archive& archive, const std::string& scan_id, int version = 0);

// The sheet of an archived scan: its current automatic set and the measurements
// staff saved, each with the path to draw.
StatusOr<storage::MeasurementSheet> archived_sheet(const storage::Archive& archive, const std::string& scan_id);

}  // namespace bodyscan::pipeline
