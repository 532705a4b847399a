// The scan archive: every scan a shop makes, kept so that it survives a power cut,
// can be reprocessed with newer algorithms, and can be erased completely when a
// customer asks (docs/archive.md).
//
// An SQLite database (WAL, synchronous=FULL, secure_delete) is the index: customers,
// calibrations, scans and their result versions, measurements, and an audit log of
// who did what. Each scan's files live in a folder of their own:
//
//   DIR/archive.db
//   DIR/scans/<scan>/manifest.json     what the folder holds, with checksums
//   DIR/scans/<scan>/raw/<name>        reprocessable raw data (stripe samples ...)
//   DIR/scans/<scan>/v<N>/<name>       results of processing run N (mesh.glb ...)
//   DIR/calibrations/<id>/calibration.json, rig.json
//
// Crash safety: files are written beside their target, fsynced and renamed; a
// scan's results are on disk (files, then manifest) before the transaction that
// declares them complete commits. Opening the archive repairs what a crash left:
// a scan still marked running is marked failed, with the reason, and its partial
// files go; result versions the index does not know are removed; temporary files
// and folders of deleted scans are cleared. Only one process opens an archive at
// a time (a lock file).
//
// Thread-safe: one connection, one lock.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/status.hpp"

namespace bodyscan::storage {

// A customer's consent to be scanned and kept: the terms they agreed to, word
// for word (what is stored, for how long, who sees it), when, and the staff
// member who recorded it.
struct Consent {
  std::string given_at;  // ISO 8601 UTC
  std::string recorded_by, terms;
};

struct Customer {
  std::string id;  // pseudonymous, random ("c_" + 16 hex digits)
  std::optional<std::string> name, contact;
  std::string created_at;          // ISO 8601 UTC
  std::optional<Consent> consent;  // the latest recorded; none: no scan may start
};

enum class ScanStatus { kRunning, kComplete, kFailed, kCancelled };
const char* to_string(ScanStatus s);

struct ArchivedFile {
  std::string name;
  uint64_t bytes = 0;
  std::string blake2b;  // hex, 256-bit
};

struct ScanVersion {
  int version = 0;
  std::string created_at;
  nlohmann::json algorithms = nlohmann::json::object();  // e.g. {"surface": "...", "measure": "..."}
  std::string note;
  std::vector<ArchivedFile> files;
};

struct ScanRecord {
  std::string id, customer_id, operator_name, calibration_id;
  ScanStatus status = ScanStatus::kRunning;
  std::string status_reason;
  std::string started_at, finished_at;
  nlohmann::json rig;       // the rig description the scan ran on
  int current_version = 0;  // 0: no results (running or failed)
  std::vector<ScanVersion> versions;
  std::vector<ArchivedFile> raw;
};

struct MeasurementRecord {
  int64_t id = 0;
  std::string scan_id;
  int version = 0;
  std::string source = "automatic";  // or "user"
  std::string name, label, kind, iso_clause;
  double value_mm = 0;
  nlohmann::json geometry = nlohmann::json::object();  // what to draw (the measurements schema)
  std::string created_by, created_at;
};

// A measurement as the API serves it and a customer's export holds it: every
// field but scan_id.
nlohmann::json to_json(const MeasurementRecord& m);

// A value a member of staff measured on the customer by hand (tape, anthropometer)
// for one of a scan's automatic measurements: the reference ISO 20685-1 compares
// scan-derived values with. One per scan and measurement; entering it again
// replaces it.
struct TapeMeasurement {
  std::string scan_id, customer_id;  // customer_id: filled in when read
  std::string name;                  // the automatic measurement's name, e.g. "waist_girth"
  double value_mm = 0;
  std::string measured_by;  // who took it
  std::string entered_by, entered_at;
};

nlohmann::json to_json(const TapeMeasurement& t);

struct AuditEntry {
  int64_t id = 0;
  std::string at, actor, action, target_kind, target_id, detail;
};

// One processing run's results.
struct ScanResults {
  std::map<std::string, std::string> files;  // name -> bytes, e.g. "mesh.glb"
  nlohmann::json algorithms = nlohmann::json::object();
  std::string note;
  std::vector<MeasurementRecord> measurements;  // the automatic set (ids, scan, version filled in)
};

struct RecoveryReport {
  std::vector<std::string> scans_failed;  // were running when the last process stopped
  size_t versions_removed = 0;            // result folders no committed version owns
  size_t orphans_removed = 0;             // folders of scans the index does not know
  size_t temp_files_removed = 0;
};

struct ScanQuery {
  std::string customer_id;  // "" any
  // Words, each found (in any order and case) in the scan id, customer id,
  // customer name or contact, or operator; at most 8.
  std::string text;
  std::string from, to;  // started_at range, ISO 8601 prefixes ("2026-11-01")
  int limit = 100;
};

class Archive {
 public:
  // Opens (creating if needed) the archive in `dir` and repairs what a crash left.
  static StatusOr<std::unique_ptr<Archive>> open(const std::string& dir);
  ~Archive();
  const RecoveryReport& recovery() const;
  std::string dir() const;

  // Customers.
  StatusOr<Customer> add_customer(const std::optional<std::string>& name, const std::optional<std::string>& contact,
                                  const std::string& actor);
  StatusOr<Customer> customer(const std::string& id) const;
  // `text`: words, each found in the id, name or contact (as ScanQuery::text).
  StatusOr<std::vector<Customer>> customers(const std::string& text = "") const;
  // Records that the customer agreed to `terms` now; the latest consent is the
  // customer's. Erasing the customer erases it.
  StatusOr<Consent> record_consent(const std::string& customer_id, const std::string& terms, const std::string& actor);
  // Everything derived from the customer goes: records, files, audit entries
  // naming them or their scans (one entry says a customer was erased, and by whom).
  Status delete_customer(const std::string& id, const std::string& actor);
  // Everything held about the customer, into `dest` (created): customer.json
  // (records, measurements, audit entries) and each scan's folder.
  Status export_customer(const std::string& id, const std::string& dest, const std::string& actor);

  // Calibrations.
  StatusOr<std::string> add_calibration(const nlohmann::json& rig, const nlohmann::json& calibration,
                                        const std::string& actor);
  StatusOr<nlohmann::json> calibration(const std::string& id) const;

  // Scans: begin, raw data as it comes, then complete (or fail) once.
  StatusOr<std::string> begin_scan(const std::string& customer_id, const std::string& operator_name,
                                   const nlohmann::json& rig, const std::string& calibration_id);
  Status put_raw(const std::string& scan_id, const std::string& name, std::string_view bytes);
  // The calibration a running scan uses, when it was made for it (after begin_scan).
  Status set_scan_calibration(const std::string& scan_id, const std::string& calibration_id);
  Status complete_scan(const std::string& scan_id, const ScanResults& results);
  // kFailed or kCancelled, with the reason. The record and the reason stay; its
  // files go, raw data included: a scan that did not complete keeps nothing of
  // the person (and a cancelled one may be a customer who changed their mind).
  Status end_scan(const std::string& scan_id, ScanStatus status, const std::string& reason);
  // Reprocessing: a new version beside the old ones, which stay.
  StatusOr<int> add_version(const std::string& scan_id, const ScanResults& results, const std::string& actor);
  Status delete_scan(const std::string& id, const std::string& actor);

  StatusOr<ScanRecord> scan(const std::string& id) const;
  StatusOr<std::vector<ScanRecord>> scans(const ScanQuery& query = {}) const;
  // The path of a result file (version 0: the current one) or, with version -1, of
  // a raw file. Not found unless the archive lists it.
  StatusOr<std::string> file_path(const std::string& scan_id, int version, const std::string& name) const;

  // Measurements: the automatic set of a version, and the ones staff save.
  StatusOr<std::vector<MeasurementRecord>> measurements(const std::string& scan_id, int version = 0) const;
  StatusOr<int64_t> save_measurement(const MeasurementRecord& m, const std::string& actor);
  Status delete_measurement(const std::string& scan_id, int64_t id, const std::string& actor);

  // Tape measurements: a scan's, or every scan's (scan_id ""), oldest first. Adding
  // one for a measurement the scan already has replaces it; the name must be one of
  // the scan's automatic measurements, the value between 1 mm and 3 m.
  StatusOr<std::vector<TapeMeasurement>> tape_measurements(const std::string& scan_id = "") const;
  Status put_tape_measurement(const TapeMeasurement& t, const std::string& actor);
  Status delete_tape_measurement(const std::string& scan_id, const std::string& name, const std::string& actor);

  // Changes whenever a scan, its versions or measurements change (through this
  // object): what is derived from them can be cached against it.
  uint64_t revision() const;

  StatusOr<std::vector<AuditEntry>> audit(const std::string& target_id = "", int limit = 1000) const;
  Status log(const std::string& actor, const std::string& action, const std::string& target_kind,
             const std::string& target_id, const std::string& detail);

  // The database's own integrity check, and every complete scan's files against
  // their checksums. Ok, or what is wrong.
  Status verify() const;

 private:
  struct Impl;
  explicit Archive(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace bodyscan::storage
