// The workstation: the rig, its calibration, the archive and the staff accounts,
// and the one job the rig runs at a time (calibrate, scan, reprocess), with the
// events browsers follow. The HTTP layer (server/api) calls it; it knows nothing
// of HTTP.
//
// Threads: a job runs on a thread of its own, never on the network threads;
// everything here may be called from any thread. Events are delivered to the
// subscribers on the job's thread (or the caller's), so a subscriber must only
// queue them (server/net does, per WebSocket session).
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "core/status.hpp"
#include "hw/sim/sim_rig.hpp"
#include "pipeline/rig_backend.hpp"
#include "recon/geometry/triangle_mesh.hpp"
#include "server/auth/auth_store.hpp"
#include "storage/archive/archive.hpp"

namespace bodyscan::server {

struct WorkstationOptions {
  std::string data_dir = "bodyscan-data";  // archive.db, scans/, accounts.db, workstation/
  std::string rig = "sim";                 // sim | thesis | square | a rig description file
  pipeline::SimulatedSubject subject;      // the simulated subject, its posture and place
  AuthOptions auth;
  int default_every = 1;  // scan every Nth laser step unless a request says
  // Live camera previews during a scan: at most one per camera this often, this wide.
  double preview_interval_s = 1.0;
  int preview_width = 320;
  // What a customer agrees to before their first scan (what is stored, for how
  // long, who sees it), shown by the station and kept word for word with the
  // consent; empty: default_consent_terms().
  std::string consent_terms;
  // Scans that started longer ago than this are erased by the workstation, at
  // open and every hour after (audit: "delete scan" by "retention"); 0 keeps
  // them until staff erase them.
  int retention_days = 0;
  // How far two scans of one customer on one day may differ, mm, before the
  // station asks for another (pipeline/repeat_scans.hpp); 0: each value's ISO
  // 20685-1 allowance.
  double repeatability_mm = 0;
  // Calibration asks a person to hold the lens dot-grid board before every real
  // camera (JobInfo::prompt). With this, before the simulated ones too: staff
  // training on the simulated rig (and the tests of the prompt).
  bool operator_dot_grid = false;
  // A prompt nobody answers in this long stops the calibration.
  double operator_timeout_s = 900;
};

enum class JobKind { kCalibrate, kScan, kReprocess, kPostureCheck };
enum class JobState { kRunning, kComplete, kFailed, kCancelled };
const char* to_string(JobKind k);
const char* to_string(JobState s);

// What a job waits for a person to do (a calibration's dot grid): answered with
// Workstation::answer_prompt, naming its id.
struct JobPrompt {
  std::string id;        // "p" + a number, new for every question
  std::string kind;      // hold_dot_grid | remove_dot_grid
  std::string camera;    // the camera's id (hold_dot_grid)
  std::string text;      // the instruction, for the station to show
  std::string why;       // why the last picture of the board could not be used
  std::string asked_at;  // ISO 8601 UTC
};

struct JobInfo {
  std::string id;  // "j_" + 16 hex digits
  JobKind kind = JobKind::kScan;
  JobState state = JobState::kRunning;
  std::string stage;    // e.g. "calibration: lens", "scan", "surface: field"
  double fraction = 0;  // of the stage
  int64_t frames = 0;   // camera frames processed so far (scans)
  std::string scan_id, customer_id, actor;
  std::string error;                    // why it failed or was cancelled
  std::string started_at, finished_at;  // ISO 8601 UTC
  int version = 0;                      // a reprocess's new version
  std::optional<JobPrompt> prompt;      // what the job waits for a person to do
  // A posture check's result (pipeline::to_json(PostureSweep)), once complete.
  nlohmann::json posture_check;
};
nlohmann::json to_json(const JobInfo& job);

struct ScanRequest {
  std::string customer_id;  // an existing customer
  int every = 0;            // 0: the workstation's default
  std::string actor;
  // The customer has just agreed to the workstation's consent terms: recorded,
  // with the time and the actor, before the scan starts.
  bool consent_given = false;
};

// The terms a customer agrees to unless the shop sets its own.
std::string default_consent_terms();

class Workstation {
 public:
  // Opens the archive and accounts in options.data_dir (created), the rig, and
  // the last calibration kept there.
  static StatusOr<std::unique_ptr<Workstation>> open(const WorkstationOptions& options);
  ~Workstation();  // shutdown("the workstation stopped")

  storage::Archive& archive();
  AuthStore& auth();
  const WorkstationOptions& options() const;
  // The simulated rig (fault injection in tests); null for a real rig.
  hw::sim::SimulatedRig* simulated_rig();

  // Cameras, lasers, the calibration (age, residuals), the job running.
  nlohmann::json rig_status() const;

  // The consent terms customers agree to (options().consent_terms or the default).
  const std::string& consent_terms() const;
  // Erases the scans older than options().retention_days at `now` (unix seconds;
  // nothing when the period is 0). Returns how many went.
  StatusOr<size_t> erase_expired_scans(int64_t now);

  // A job, started when the rig is free; failed_precondition ("the rig is busy
  // with ...") when another runs. The scan is in the archive, as running, before
  // this returns (so a crash leaves a scan marked failed, never a silent gap).
  // A scan starts only for a customer whose consent is on record or given with
  // the request (failed_precondition otherwise, nothing stored).
  StatusOr<JobInfo> start_calibration(const std::string& actor);
  StatusOr<JobInfo> start_scan(const ScanRequest& request);
  StatusOr<JobInfo> start_reprocess(const std::string& scan_id, const std::string& actor);
  // A quick coarse sweep that reads how the customer stands (pipeline/posture_sweep.hpp),
  // before the full scan; nothing is stored. The result is in the job's
  // `posture_check` when it completes.
  StatusOr<JobInfo> start_posture_check(const std::string& actor);
  // Asks the job to stop (it stops at the next frame or stage, lasers off).
  Status cancel(const std::string& job_id, const std::string& actor);
  // The person has done what the job's prompt asked: not_found for another job,
  // failed_precondition when the job asks nothing or asks something newer.
  Status answer_prompt(const std::string& job_id, const std::string& prompt_id);
  std::optional<JobInfo> job(const std::string& id) const;  // the current or the last job
  std::optional<JobInfo> current_job() const;               // running
  // Waits until no job runs (tests, shutdown); false on timeout.
  bool wait_idle(double timeout_s) const;

  // Events as JSON text (docs/api.md): {"type": "job" | "preview" | "rig" | "scan_finished", ...}.
  using EventSink = std::function<void(std::shared_ptr<const std::string>)>;
  int subscribe(EventSink sink);
  void unsubscribe(int id);

  // A scan's surface (version 0: the current one), decoded once and kept for the
  // next measurement (a few recent scans).
  StatusOr<std::shared_ptr<const TriangleMesh>> surface(const std::string& scan_id, int version = 0);

  // A response body derived from the archive (a scan's measurements ...), made
  // once per change of the archive (Archive::revision) and kept with its gzip
  // form and an ETag, so that fifty tablets asking for it cost one parse.
  struct CachedText {
    std::string body, gzip, etag;  // etag quoted, as sent
  };
  StatusOr<std::shared_ptr<const CachedText>> cached_text(const std::string& key,
                                                          const std::function<StatusOr<std::string>()>& make);

  // Cancels the job (marking it and its scan with `reason`), waits for it, turns
  // every laser off. Idempotent.
  void shutdown(const std::string& reason);

 private:
  struct Impl;
  explicit Workstation(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace bodyscan::server
