#include "server/workstation/workstation.hpp"

#include <sodium.h>
#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <list>
#include <map>
#include <mutex>
#include <thread>

#include <zlib.h>

#include "core/json_text.hpp"
#include "hw/rig_description.hpp"
#include "pipeline/archive_scan.hpp"
#include "pipeline/posture_sweep.hpp"
#include "pipeline/rig_backend.hpp"
#include "pipeline/scan_job.hpp"
#include "pipeline/scan_recording.hpp"
#include "recon/io/atomic_file.hpp"
#include "server/workstation/erasure.hpp"
#include "server/workstation/preview.hpp"
#include "storage/archive/ids.hpp"

namespace bodyscan::server {

const char* to_string(JobKind k) {
  switch (k) {
    case JobKind::kCalibrate: return "calibrate";
    case JobKind::kScan: return "scan";
    case JobKind::kReprocess: return "reprocess";
    case JobKind::kPostureCheck: return "posture_check";
  }
  return "?";
}

const char* to_string(JobState s) {
  switch (s) {
    case JobState::kRunning: return "running";
    case JobState::kComplete: return "complete";
    case JobState::kFailed: return "failed";
    case JobState::kCancelled: return "cancelled";
  }
  return "?";
}

nlohmann::json to_json(const JobInfo& j) {
  nlohmann::json out = {{"id", j.id},       {"kind", to_string(j.kind)}, {"state", to_string(j.state)},
                        {"stage", j.stage}, {"fraction", j.fraction},    {"frames", j.frames},
                        {"actor", j.actor}, {"started_at", j.started_at}};
  if (!j.scan_id.empty()) out["scan_id"] = j.scan_id;
  if (!j.customer_id.empty()) out["customer_id"] = j.customer_id;
  if (!j.error.empty()) out["error"] = j.error;
  if (!j.finished_at.empty()) out["finished_at"] = j.finished_at;
  if (j.version > 0) out["version"] = j.version;
  if (!j.posture_check.is_null()) out["posture_check"] = j.posture_check;
  if (j.prompt) {
    const JobPrompt& p = *j.prompt;
    out["prompt"] = {{"id", p.id}, {"kind", p.kind}, {"text", p.text}, {"asked_at", p.asked_at}};
    if (!p.camera.empty()) out["prompt"]["camera"] = p.camera;
    if (!p.why.empty()) out["prompt"]["why"] = p.why;
  } else {
    out["prompt"] = nullptr;
  }
  return out;
}

namespace {

int64_t unix_now() { return static_cast<int64_t>(std::time(nullptr)); }

std::string base64(const std::string& bytes) {
  std::string out(sodium_base64_encoded_len(bytes.size(), sodium_base64_VARIANT_ORIGINAL), '\0');
  sodium_bin2base64(out.data(), out.size(), reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(),
                    sodium_base64_VARIANT_ORIGINAL);
  out.pop_back();  // the terminating NUL
  return out;
}

std::string gzip(const std::string& in) {
  z_stream z{};
  if (deflateInit2(&z, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK) return {};
  std::string out(deflateBound(&z, in.size()) + 32, '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data()));
  z.avail_in = static_cast<uInt>(in.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  const int rc = deflate(&z, Z_FINISH);
  out.resize(z.total_out);
  deflateEnd(&z);
  return rc == Z_STREAM_END ? out : std::string();
}

constexpr int kJobNice = 5;

constexpr const char* kCalibrationFile = "calibration-record.json";  // in DATA/workstation/

}  // namespace

struct Workstation::Impl {
  WorkstationOptions options;
  std::string consent_terms;  // options.consent_terms or the default
  std::unique_ptr<storage::Archive> archive;
  std::unique_ptr<AuthStore> auth;
  std::unique_ptr<hw::DeviceRig> devices;
  pipeline::Rig rig;
  nlohmann::json rig_json;  // the description, as the archive records it

  mutable std::mutex mutex;  // everything below
  mutable std::condition_variable idle_cv;
  std::optional<pipeline::RigCalibration> calibration;
  std::string calibration_id;  // in the archive
  int64_t calibrated_at = 0;   // unix seconds
  std::optional<JobInfo> job;  // the current or last
  bool running = false;
  std::atomic<bool> cancel{false};
  std::string cancel_reason;
  std::thread worker;
  std::thread retention;  // erases expired scans hourly (options.retention_days)
  std::condition_variable retention_cv;
  std::vector<std::thread> retired;  // finished jobs' threads, joined at shutdown
  bool stopped = false;
  std::condition_variable prompt_cv;  // a prompt answered, a job cancelled
  int prompt_seq = 0;
  std::map<int, EventSink> sinks;
  int next_sink = 1;
  std::string last_camera_error;

  std::mutex text_mutex;
  std::map<std::string, std::pair<uint64_t, std::shared_ptr<const CachedText>>> texts;  // key -> (revision, text)
  static constexpr size_t kTextCacheSize = 32;

  std::mutex cache_mutex;
  std::list<std::pair<std::string, std::shared_ptr<const TriangleMesh>>> cache;  // most recent first
  static constexpr size_t kCacheSize = 4;

  void publish(const nlohmann::json& event) {
    auto text = std::make_shared<const std::string>(event.dump());
    std::vector<EventSink> to_call;
    {
      std::lock_guard lock(mutex);
      for (auto& [id, s] : sinks) to_call.push_back(s);
    }
    for (auto& s : to_call) s(text);
  }
  void publish_job() {
    nlohmann::json j;
    {
      std::lock_guard lock(mutex);
      if (!job) return;
      j = to_json(*job);
    }
    publish({{"type", "job"}, {"job", j}});
  }

  nlohmann::json calibration_json() const {  // under mutex
    if (!calibration) return nullptr;
    nlohmann::json cams = nlohmann::json::array();
    for (const CameraCalibration& c : calibration->cameras)
      cams.push_back({{"id", c.camera_id},
                      {"side", to_string(c.side)},
                      {"lens_held_out_rms_px", c.lens.held_out_rms_px()},
                      {"ray_spread_mm", c.ray_spread_mm}});
    return {{"id", calibration_id},
            {"calibrated_at", calibrated_at},
            {"age_s", std::max<int64_t>(0, unix_now() - calibrated_at)},
            {"cameras", cams},
            {"group_separation_mm", calibration->group_separation_mm}};
  }

  Status save_calibration(const pipeline::RigCalibration& cal, const std::string& actor) {
    ASSIGN_OR_RETURN(std::string id, archive->add_calibration(rig_json, pipeline::to_json(cal), actor));
    nlohmann::json keep = {{"calibration_id", id},
                           {"calibrated_at", unix_now()},
                           {"rig", rig_json.value("name", "")},
                           {"record", pipeline::calibration_record(cal)}};
    const std::string dir = options.data_dir + "/workstation";
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    RETURN_IF_ERROR(write_file_atomically(dir + "/" + kCalibrationFile, keep.dump()));
    std::lock_guard lock(mutex);
    calibration = cal;
    calibration_id = id;
    calibrated_at = keep["calibrated_at"].get<int64_t>();
    return Status::Ok();
  }

  // The calibration the last run kept, if it was made for this rig.
  void load_calibration() {
    const std::string path = options.data_dir + "/workstation/" + kCalibrationFile;
    if (!std::filesystem::exists(path)) return;
    StatusOr<std::string> text = read_whole_file(path);
    if (!text.ok()) return;
    const nlohmann::json keep = parse_json(*text);
    if (keep.is_discarded() || keep.value("rig", "") != rig_json.value("name", "")) return;
    StatusOr<pipeline::RigCalibration> cal = pipeline::calibration_from_record(keep.value("record", nlohmann::json()));
    if (!cal.ok()) return;
    calibration = std::move(*cal);
    calibration_id = keep.value("calibration_id", "");
    calibrated_at = keep.value("calibrated_at", int64_t{0});
  }

  // With none kept, the newest archived scan made on this rig (by `bodyscan scan
  // --archive`, say) carries its calibration in its raw record: the rig's last.
  void load_calibration_from_archive() {
    if (calibration) return;
    storage::ScanQuery q;
    q.limit = 20;
    StatusOr<std::vector<storage::ScanRecord>> scans = archive->scans(q);
    if (!scans.ok()) return;
    for (const storage::ScanRecord& r : *scans) {
      if (r.status != storage::ScanStatus::kComplete || !r.rig.is_object() ||
          r.rig.value("name", "") != rig_json.value("name", ""))
        continue;
      StatusOr<std::string> path = archive->file_path(r.id, -1, pipeline::kRawRecordFile);
      if (!path.ok()) continue;
      StatusOr<std::string> text = read_whole_file(*path);
      if (!text.ok()) continue;
      StatusOr<pipeline::RigCalibration> cal = pipeline::calibration_from_record(parse_json(*text));
      if (!cal.ok()) continue;
      std::tm tm{};
      if (!strptime(r.started_at.c_str(), "%Y-%m-%dT%H:%M:%S", &tm)) continue;
      calibration = std::move(*cal);
      calibration_id = r.calibration_id;
      calibrated_at = static_cast<int64_t>(timegm(&tm));
      return;
    }
  }

  StatusOr<JobInfo> begin(JobKind kind, const std::string& actor) {  // under mutex
    if (stopped) return failed_precondition("the workstation is stopping");
    if (running) {
      return failed_precondition(std::string("the rig is busy with a ") + to_string(job->kind) + " (job " + job->id +
                                 "); cancel it or wait for it to finish");
    }
    // The last job's thread is done with its work but may still be telling
    // subscribers so; it is joined later, off this lock (see shutdown).
    if (worker.joinable()) retired.push_back(std::move(worker));
    JobInfo j;
    j.id = "j_" + storage::random_hex(8);
    j.kind = kind;
    j.actor = actor;
    j.started_at = storage::iso8601_utc(unix_now());
    j.stage = "starting";
    cancel = false;
    cancel_reason.clear();
    return j;
  }

  ProgressFn progress_fn() {
    auto last = std::make_shared<std::chrono::steady_clock::time_point>();
    auto last_stage = std::make_shared<std::string>();
    return [this, last, last_stage](std::string_view stage, double fraction) {
      const auto now = std::chrono::steady_clock::now();
      bool send = false;
      {
        std::lock_guard lock(mutex);
        job->stage = std::string(stage);
        job->fraction = fraction;
        // Ten updates a second at most, and every change of stage.
        if (*last_stage != stage || now - *last > std::chrono::milliseconds(100) || fraction >= 1.0) {
          send = true;
          *last = now;
          *last_stage = std::string(stage);
        }
      }
      if (send) publish_job();
      return !cancel.load();
    };
  }

  // Joins the threads of jobs that have ended (off the lock: they may still be
  // publishing their last events, which takes it).
  void reap() {
    std::vector<std::thread> done;
    {
      std::lock_guard lock(mutex);
      done = std::move(retired);
      retired.clear();
      if (!running && worker.joinable()) done.push_back(std::move(worker));
    }
    for (std::thread& t : done) t.join();
  }
  nlohmann::json status_json() const;  // takes the mutex
  void publish_rig() { publish({{"type", "rig"}, {"rig", status_json()}}); }
  void run(JobInfo j, std::function<Status()> work);
  Status ask_operator(const pipeline::OperatorRequest& request);
  Status do_calibrate();
  Status do_scan(int every);
  Status do_reprocess(const std::string& scan_id, const std::string& actor);
  Status do_posture_check();
  std::function<void(const pipeline::Shot&)> preview_fn();
  // The rig's calibration, made first (and kept) when there is none yet.
  StatusOr<pipeline::RigCalibration> calibration_or_calibrate(const std::string& actor);
};

Workstation::Workstation(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Workstation::~Workstation() { shutdown("the workstation stopped"); }

StatusOr<std::unique_ptr<Workstation>> Workstation::open(const WorkstationOptions& options) {
  if (sodium_init() < 0) return internal_error("libsodium failed to start");
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  impl->consent_terms = options.consent_terms.empty() ? default_consent_terms() : options.consent_terms;
  std::error_code ec;
  std::filesystem::create_directories(options.data_dir, ec);
  if (ec) return io_error(options.data_dir + ": cannot create the data folder: " + ec.message());
  ASSIGN_OR_RETURN(impl->archive, storage::Archive::open(options.data_dir));
  ASSIGN_OR_RETURN(impl->auth, AuthStore::open(options.data_dir + "/accounts.db", options.auth));
  ASSIGN_OR_RETURN(impl->devices, pipeline::open_rig(options.rig, options.subject));
  Impl* ip = impl.get();
  impl->rig = pipeline::rig_handle(
      *impl->devices, [ip](const pipeline::OperatorRequest& r) { return ip->ask_operator(r); },
      options.operator_dot_grid);
  impl->rig_json = nlohmann::json::parse(hw::to_json(impl->devices->description()), nullptr, false);
  // Whatever state the rig was left in, no laser shines until a scan asks.
  RETURN_IF_ERROR(impl->rig.controller->all_lasers_off());
  impl->load_calibration();
  impl->load_calibration_from_archive();
  auto ws = std::unique_ptr<Workstation>(new Workstation(std::move(impl)));
  if (options.retention_days > 0) {
    RETURN_IF_ERROR(ws->erase_expired_scans(unix_now()).status());
    Workstation* w = ws.get();
    ip->retention = std::thread([w, ip]() {
      std::unique_lock lock(ip->mutex);
      while (!ip->retention_cv.wait_for(lock, std::chrono::hours(1), [ip] { return ip->stopped; })) {
        lock.unlock();
        // A failure (a full disk) is retried in an hour; the scans stay meanwhile.
        if (StatusOr<size_t> n = w->erase_expired_scans(unix_now()); !n.ok())
          std::fprintf(stderr, "bodyscan: retention: %s\n", n.status().message().c_str());
        lock.lock();
      }
    });
  }
  return ws;
}

StatusOr<size_t> Workstation::erase_expired_scans(int64_t now) {
  const int days = impl_->options.retention_days;
  if (days <= 0) return size_t{0};
  const std::string before = storage::iso8601_utc(now - int64_t{days} * 86400);
  ASSIGN_OR_RETURN(std::vector<std::string> erased,
                   erase_scans_started_before(*impl_->archive, impl_->auth.get(), before,
                                              "retention (" + std::to_string(days) + " days)"));
  if (!erased.empty())
    std::fprintf(stderr, "bodyscan: retention: erased %zu scan(s) started before %s\n", erased.size(), before.c_str());
  return erased.size();
}

storage::Archive& Workstation::archive() { return *impl_->archive; }
AuthStore& Workstation::auth() { return *impl_->auth; }
const WorkstationOptions& Workstation::options() const { return impl_->options; }
hw::sim::SimulatedRig* Workstation::simulated_rig() { return impl_->devices->simulation(); }

nlohmann::json Workstation::Impl::status_json() const {
  const Impl& s = *this;
  std::lock_guard lock(s.mutex);
  nlohmann::json cams = nlohmann::json::array();
  for (hw::Camera* c : s.rig.cameras) {
    const hw::CameraInfo& info = c->info();
    cams.push_back({{"id", info.id},
                    {"vendor", info.vendor},
                    {"model", info.model},
                    {"serial", info.serial},
                    {"width", info.width},
                    {"height", info.height}});
  }
  nlohmann::json lasers = nlohmann::json::array();
  const auto& desc = *s.rig.description;
  for (size_t i = 0; i < desc.lasers.size(); ++i) {
    // While a job runs the job owns the controller; the lasers are its to switch.
    nlohmann::json l = {{"id", desc.lasers[i].id}};
    if (s.running)
      l["on"] = nullptr;
    else
      l["on"] = s.rig.controller->laser_on(static_cast<int>(i));
    lasers.push_back(l);
  }
  nlohmann::json out = {{"rig", desc.name},
                        {"simulated", !s.devices->description().has_real_devices()},
                        {"cameras", cams},
                        {"lasers", lasers},
                        {"calibration", s.calibration_json()},
                        {"busy", s.running},
                        {"job", s.running && s.job ? to_json(*s.job) : nlohmann::json(nullptr)}};
  if (!s.last_camera_error.empty()) out["last_device_error"] = s.last_camera_error;
  return out;
}

nlohmann::json Workstation::rig_status() const { return impl_->status_json(); }

void Workstation::Impl::run(JobInfo j, std::function<Status()> work) {
  job = j;
  running = true;
  worker = std::thread([this, work = std::move(work)]() {
    // A scan is batch work beside the staff's clicks: a little lower priority keeps
    // the API's answers quick while both want the cores (docs/benchmarks.md §9).
    // Mild, so that a real rig's acquisition still keeps pace with its cameras.
    setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), kJobNice);
    publish_job();
    publish_rig();
    Status st;
    try {
      st = work();
    } catch (const std::exception& e) {
      st = internal_error(std::string("the job stopped on an unexpected error: ") + e.what());
    }
    // Whatever happened, the lasers go off before anyone hears the job ended.
    const Status off = rig.controller->all_lasers_off();
    nlohmann::json finished;
    {
      std::lock_guard lock(mutex);
      job->finished_at = storage::iso8601_utc(unix_now());
      if (st.ok()) {
        job->state = JobState::kComplete;
        job->fraction = 1;
      } else if (st.code() == StatusCode::kCancelled || cancel) {
        job->state = JobState::kCancelled;
        job->error = cancel_reason.empty() ? st.message() : cancel_reason;
      } else {
        job->state = JobState::kFailed;
        job->error = st.message();
        if (st.code() == StatusCode::kUnavailable || st.code() == StatusCode::kDeadlineExceeded)
          last_camera_error = st.message();
      }
      if (!off.ok()) job->error += (job->error.empty() ? "" : "; ") + ("lasers: " + off.message());
      if (job->kind == JobKind::kScan) finished = to_json(*job);
      running = false;
    }
    publish_job();
    if (!finished.is_null()) publish({{"type", "scan_finished"}, {"job", finished}});
    publish_rig();
    idle_cv.notify_all();
  });
}

// On the job's thread: shows the request as the job's prompt and waits for the
// answer, a cancel or the timeout.
Status Workstation::Impl::ask_operator(const pipeline::OperatorRequest& request) {
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                             std::chrono::duration<double>(options.operator_timeout_s));
  std::string id;
  {
    std::lock_guard lock(mutex);
    if (!job || !running) return failed_precondition("no job to ask the operator for");
    JobPrompt p;
    p.id = "p" + std::to_string(++prompt_seq);
    p.kind = pipeline::to_string(request.kind);
    if (request.kind == pipeline::OperatorRequest::Kind::kHoldDotGrid) p.camera = request.camera_id;
    p.text = request.text();
    p.why = request.why;
    p.asked_at = storage::iso8601_utc(unix_now());
    id = p.id;
    job->prompt = std::move(p);
  }
  publish_job();
  bool answered = false;
  {
    std::unique_lock lock(mutex);
    prompt_cv.wait_until(lock, deadline, [&] { return !job->prompt || job->prompt->id != id || cancel; });
    answered = !job->prompt || job->prompt->id != id;
    job->prompt.reset();
  }
  publish_job();
  if (cancel) return cancelled("calibration cancelled");
  if (!answered) {
    const double t = options.operator_timeout_s;
    const std::string waited = t < 120 ? std::to_string(static_cast<int>(std::lround(t))) + " s"
                                       : std::to_string(static_cast<int>(std::lround(t / 60))) + " minutes";
    // Not a device's fault (deadline_exceeded would be reported as one).
    return failed_precondition("nobody confirmed the dot-grid board in " + waited +
                               "; calibrate again when someone can hold it");
  }
  return Status::Ok();
}

Status Workstation::Impl::do_calibrate() {
  ASSIGN_OR_RETURN(pipeline::RigCalibration cal, pipeline::calibrate_rig(rig, {}, progress_fn()));
  std::string actor;
  {
    std::lock_guard lock(mutex);
    actor = job->actor;
  }
  return save_calibration(cal, actor);
}

// Previews: a small image per camera now and then, and the frame count.
std::function<void(const pipeline::Shot&)> Workstation::Impl::preview_fn() {
  auto last_preview = std::make_shared<std::map<size_t, std::chrono::steady_clock::time_point>>();
  return [this, last_preview](const pipeline::Shot& shot) {
    std::string job_id;
    {
      std::lock_guard lock(mutex);
      ++job->frames;
      job_id = job->id;
    }
    const auto now = std::chrono::steady_clock::now();
    auto it = last_preview->find(shot.camera);
    if (it != last_preview->end() && now - it->second < std::chrono::duration<double>(options.preview_interval_s))
      return;
    (*last_preview)[shot.camera] = now;
    StatusOr<std::string> png = preview_png(shot.frame, options.preview_width);
    if (!png.ok()) return;
    const std::string cam = shot.camera < rig.cameras.size() ? rig.cameras[shot.camera]->info().id : "";
    publish({{"type", "preview"},
             {"job", job_id},
             {"camera", cam},
             {"frame_id", shot.frame.frame_id},
             {"png_base64", base64(*png)}});
  };
}

StatusOr<pipeline::RigCalibration> Workstation::Impl::calibration_or_calibrate(const std::string& actor) {
  {
    std::lock_guard lock(mutex);
    if (calibration) return *calibration;
  }
  // The first scan (or posture check) on a new rig calibrates it first.
  ASSIGN_OR_RETURN(pipeline::RigCalibration made, pipeline::calibrate_rig(rig, {}, progress_fn()));
  RETURN_IF_ERROR(save_calibration(made, actor));
  return made;
}

Status Workstation::Impl::do_scan(int every) {
  std::string scan_id, actor;
  {
    std::lock_guard lock(mutex);
    scan_id = job->scan_id;
    actor = job->actor;
  }
  auto fail = [&](const Status& st) {
    const bool cancelled = st.code() == StatusCode::kCancelled || cancel;
    std::string reason;
    {
      std::lock_guard lock(mutex);
      reason = cancelled && !cancel_reason.empty() ? cancel_reason : st.message();
    }
    archive->end_scan(scan_id, cancelled ? storage::ScanStatus::kCancelled : storage::ScanStatus::kFailed, reason);
    return st;
  };
  StatusOr<pipeline::RigCalibration> cal = calibration_or_calibrate(actor);
  if (!cal.ok()) return fail(cal.status());
  {
    std::string cal_id;
    {
      std::lock_guard lock(mutex);
      cal_id = calibration_id;
    }
    if (!cal_id.empty()) archive->set_scan_calibration(scan_id, cal_id);
  }
  pipeline::ScanJobOptions o;
  o.every = every;
  o.progress = progress_fn();
  o.on_scan_shot = preview_fn();
  StatusOr<pipeline::ScanJobResult> result = pipeline::run_scan_job(rig, std::move(*cal), o);
  // The scan is over: nothing left for the lasers to do while the surface is built
  // (run_scan_job's acquisition already switched them off; this is belt and braces).
  rig.controller->all_lasers_off();
  if (!result.ok()) return fail(result.status());
  // A failed surface still archives: the cloud is good, the reason goes in the
  // version's note.
  const Status stored = pipeline::archive_scan(*archive, scan_id, *result, o);
  if (!stored.ok()) return fail(Status(stored.code(), "could not store the results: " + stored.message()));
  return Status::Ok();
}

Status Workstation::Impl::do_reprocess(const std::string& scan_id, const std::string& actor) {
  pipeline::ScanJobOptions o;
  o.progress = progress_fn();
  ASSIGN_OR_RETURN(int version, pipeline::reprocess_archived_scan(*archive, scan_id, o, actor));
  std::lock_guard lock(mutex);
  job->version = version;
  return Status::Ok();
}

Status Workstation::Impl::do_posture_check() {
  std::string actor;
  {
    std::lock_guard lock(mutex);
    actor = job->actor;
  }
  ASSIGN_OR_RETURN(pipeline::RigCalibration cal, calibration_or_calibrate(actor));
  pipeline::PostureSweepOptions o;
  o.progress = progress_fn();
  o.on_scan_shot = preview_fn();
  ASSIGN_OR_RETURN(pipeline::PostureSweep sweep, pipeline::sweep_posture(rig, std::move(cal), o));
  std::lock_guard lock(mutex);
  job->posture_check = pipeline::to_json(sweep);
  return Status::Ok();
}

StatusOr<JobInfo> Workstation::start_posture_check(const std::string& actor) {
  Impl& s = *impl_;
  s.reap();
  std::lock_guard lock(s.mutex);
  ASSIGN_OR_RETURN(JobInfo j, s.begin(JobKind::kPostureCheck, actor));
  s.run(j, [&s]() { return s.do_posture_check(); });
  return j;
}

StatusOr<JobInfo> Workstation::start_calibration(const std::string& actor) {
  Impl& s = *impl_;
  s.reap();
  std::lock_guard lock(s.mutex);
  ASSIGN_OR_RETURN(JobInfo j, s.begin(JobKind::kCalibrate, actor));
  s.run(j, [&s]() { return s.do_calibrate(); });
  return j;
}

std::string default_consent_terms() {
  return "The shop keeps your name and contact, a 3-D model of your body's shape as the scanner sees it, your body "
         "measurements, and the scanner's recordings (from which the model and measurements can be made again). "
         "It keeps them until you ask the shop to erase them, which you may do at any time: everything about you is "
         "then erased. The shop's staff see them on the shop's workstation; you see your model and the "
         "measurements the staff choose through a private link the shop gives you. Nothing leaves the shop "
         "otherwise.";
}

const std::string& Workstation::consent_terms() const { return impl_->consent_terms; }

StatusOr<JobInfo> Workstation::start_scan(const ScanRequest& request) {
  Impl& s = *impl_;
  s.reap();
  const int every = request.every > 0 ? request.every : s.options.default_every;
  if (every > 1000) return invalid_argument("'every' must be between 1 and 1000");
  ASSIGN_OR_RETURN(storage::Customer customer, s.archive->customer(request.customer_id));
  if (!customer.consent && !request.consent_given)
    return failed_precondition("customer " + customer.id +
                               " has not consented to be scanned: record their consent first (GET /api/consent "
                               "gives the terms)");
  std::lock_guard lock(s.mutex);
  ASSIGN_OR_RETURN(JobInfo j, s.begin(JobKind::kScan, request.actor));
  // Recorded once the rig is known to be free, so that a refused start records nothing.
  if (request.consent_given) {
    RETURN_IF_ERROR(s.archive->record_consent(customer.id, s.consent_terms, request.actor).status());
  }
  ASSIGN_OR_RETURN(j.scan_id, s.archive->begin_scan(customer.id, request.actor, s.rig_json, s.calibration_id));
  j.customer_id = customer.id;
  s.run(j, [&s, every]() { return s.do_scan(every); });
  return j;
}

StatusOr<JobInfo> Workstation::start_reprocess(const std::string& scan_id, const std::string& actor) {
  Impl& s = *impl_;
  s.reap();
  ASSIGN_OR_RETURN(storage::ScanRecord r, s.archive->scan(scan_id));
  if (r.raw.empty()) return failed_precondition("scan " + scan_id + " has no raw record to reprocess");
  std::lock_guard lock(s.mutex);
  ASSIGN_OR_RETURN(JobInfo j, s.begin(JobKind::kReprocess, actor));
  j.scan_id = r.id;
  j.customer_id = r.customer_id;
  s.run(j, [&s, id = r.id, actor]() { return s.do_reprocess(id, actor); });
  return j;
}

Status Workstation::cancel(const std::string& job_id, const std::string& actor) {
  Impl& s = *impl_;
  std::lock_guard lock(s.mutex);
  if (!s.job || s.job->id != job_id) return not_found("no job " + job_id);
  if (!s.running) return failed_precondition("job " + job_id + " has already ended (" + to_string(s.job->state) + ")");
  s.cancel_reason = "cancelled by " + actor;
  s.cancel = true;
  s.prompt_cv.notify_all();
  return Status::Ok();
}

Status Workstation::answer_prompt(const std::string& job_id, const std::string& prompt_id) {
  Impl& s = *impl_;
  {
    std::lock_guard lock(s.mutex);
    if (!s.job || s.job->id != job_id) return not_found("no job " + job_id);
    if (!s.running)
      return failed_precondition("job " + job_id + " has already ended (" + to_string(s.job->state) + ")");
    if (!s.job->prompt) return failed_precondition("job " + job_id + " is not waiting for anyone");
    if (s.job->prompt->id != prompt_id) {
      return failed_precondition("job " + job_id + " now asks " + s.job->prompt->id + " (\"" + s.job->prompt->text +
                                 "\"), not " + prompt_id);
    }
    s.job->prompt.reset();
  }
  s.prompt_cv.notify_all();
  return Status::Ok();
}

std::optional<JobInfo> Workstation::job(const std::string& id) const {
  std::lock_guard lock(impl_->mutex);
  if (impl_->job && impl_->job->id == id) return impl_->job;
  return std::nullopt;
}

std::optional<JobInfo> Workstation::current_job() const {
  std::lock_guard lock(impl_->mutex);
  if (impl_->running) return impl_->job;
  return std::nullopt;
}

bool Workstation::wait_idle(double timeout_s) const {
  std::unique_lock lock(impl_->mutex);
  return impl_->idle_cv.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return !impl_->running; });
}

int Workstation::subscribe(EventSink sink) {
  std::lock_guard lock(impl_->mutex);
  const int id = impl_->next_sink++;
  impl_->sinks[id] = std::move(sink);
  return id;
}

void Workstation::unsubscribe(int id) {
  std::lock_guard lock(impl_->mutex);
  impl_->sinks.erase(id);
}

StatusOr<std::shared_ptr<const TriangleMesh>> Workstation::surface(const std::string& scan_id, int version) {
  Impl& s = *impl_;
  if (version == 0) {
    ASSIGN_OR_RETURN(storage::ScanRecord r, s.archive->scan(scan_id));
    if (r.current_version == 0) return failed_precondition("scan " + scan_id + " has no results yet");
    version = r.current_version;
  }
  const std::string key = scan_id + "/v" + std::to_string(version);
  {
    std::lock_guard lock(s.cache_mutex);
    for (auto it = s.cache.begin(); it != s.cache.end(); ++it)
      if (it->first == key) {
        s.cache.splice(s.cache.begin(), s.cache, it);
        return it->second;
      }
  }
  ASSIGN_OR_RETURN(TriangleMesh mesh, pipeline::archived_surface(*s.archive, scan_id, version));
  auto shared = std::make_shared<const TriangleMesh>(std::move(mesh));
  std::lock_guard lock(s.cache_mutex);
  s.cache.emplace_front(key, shared);
  if (s.cache.size() > Impl::kCacheSize) s.cache.pop_back();
  return shared;
}

StatusOr<std::shared_ptr<const Workstation::CachedText>> Workstation::cached_text(
    const std::string& key, const std::function<StatusOr<std::string>()>& make) {
  Impl& s = *impl_;
  const uint64_t revision = s.archive->revision();
  {
    std::lock_guard lock(s.text_mutex);
    auto it = s.texts.find(key);
    if (it != s.texts.end() && it->second.first == revision) return it->second.second;
  }
  ASSIGN_OR_RETURN(std::string body, make());
  auto text = std::make_shared<CachedText>();
  unsigned char h[16];
  crypto_generichash(h, sizeof h, reinterpret_cast<const unsigned char*>(body.data()), body.size(), nullptr, 0);
  char hex[33];
  sodium_bin2hex(hex, sizeof hex, h, sizeof h);
  text->etag = std::string("\"") + hex + "\"";
  text->gzip = gzip(body);
  text->body = std::move(body);
  std::lock_guard lock(s.text_mutex);
  if (s.texts.size() >= Impl::kTextCacheSize) s.texts.clear();  // rarely reached: a shop looks at a few scans
  s.texts[key] = {revision, text};
  return std::shared_ptr<const CachedText>(text);
}

void Workstation::shutdown(const std::string& reason) {
  Impl& s = *impl_;
  {
    std::lock_guard lock(s.mutex);
    s.stopped = true;
    if (s.running) {
      s.cancel_reason = "cancelled: " + reason;
      s.cancel = true;
    }
  }
  s.prompt_cv.notify_all();
  s.retention_cv.notify_all();
  if (s.retention.joinable()) s.retention.join();
  std::vector<std::thread> threads;
  {
    std::lock_guard lock(s.mutex);
    threads = std::move(s.retired);
    s.retired.clear();
    if (s.worker.joinable()) threads.push_back(std::move(s.worker));
  }
  for (std::thread& t : threads) t.join();
  if (s.rig.controller) s.rig.controller->all_lasers_off();
  std::lock_guard lock(s.mutex);
  s.sinks.clear();
}

}  // namespace bodyscan::server
