#include "storage/archive/archive.hpp"

#include <fcntl.h>
#include <sodium.h>
#include <sys/file.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <mutex>
#include <set>
#include <sstream>

#include "core/json_text.hpp"
#include "recon/io/atomic_file.hpp"
#include "storage/archive/ids.hpp"
#include "storage/archive/sqlite.hpp"

namespace bodyscan::storage {

namespace fs = std::filesystem;

const char* to_string(ScanStatus s) {
  switch (s) {
    case ScanStatus::kRunning: return "running";
    case ScanStatus::kComplete: return "complete";
    case ScanStatus::kFailed: return "failed";
    case ScanStatus::kCancelled: return "cancelled";
  }
  return "?";
}

namespace {

constexpr int kSchemaVersion = 1;
constexpr int kRawVersion = -1;  // scan_files.version of raw data
constexpr const char* kInterrupted =
    "interrupted: the workstation stopped while the scan was running (power cut or crash); scan again";

ScanStatus parse_status(const std::string& s) {
  if (s == "complete") return ScanStatus::kComplete;
  if (s == "failed") return ScanStatus::kFailed;
  if (s == "cancelled") return ScanStatus::kCancelled;
  return ScanStatus::kRunning;
}

std::string now_iso() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm utc{};
  gmtime_r(&t, &utc);
  char b[40];
  std::strftime(b, sizeof b, "%Y-%m-%dT%H:%M:%S", &utc);
  char out[48];
  std::snprintf(out, sizeof out, "%s.%03dZ", b, static_cast<int>(ms));
  return out;
}

// "s_20261122_101530_" + 8 hex digits: sorts by time, unguessable enough to be no
// one's business, short enough to read out.
std::string new_id(char kind) {
  const std::time_t t = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&t, &utc);
  char b[32];
  std::strftime(b, sizeof b, "%Y%m%d_%H%M%S", &utc);
  return std::string(1, kind) + "_" + b + "_" + random_hex(4);
}

std::string blake2b_hex(std::string_view bytes) {
  unsigned char h[32];
  crypto_generichash(h, sizeof h, reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), nullptr, 0);
  char hex[65];
  sodium_bin2hex(hex, sizeof hex, h, sizeof h);
  return hex;
}

// File names the archive accepts: letters, digits, '.', '_', '-', not starting with
// '.', at most 100 characters. Ids: the same, as the archive makes them.
bool safe_name(const std::string& n) {
  if (n.empty() || n.size() > 100 || n[0] == '.') return false;
  for (char c : n)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-') return false;
  return true;
}

StatusOr<std::string> slurp(const fs::path& p) { return read_whole_file(p.string()); }

void sync_dir(const fs::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
}

Status make_dirs(const fs::path& p) {
  std::error_code ec;
  fs::create_directories(p, ec);
  if (ec) return io_error("archive: cannot create " + p.string() + ": " + ec.message());
  return Status::Ok();
}

nlohmann::json file_json(const ArchivedFile& f) {
  return {{"name", f.name}, {"bytes", f.bytes}, {"blake2b", f.blake2b}};
}

}  // namespace

nlohmann::json to_json(const MeasurementRecord& m) {
  return {{"id", m.id},
          {"version", m.version},
          {"source", m.source},
          {"name", m.name},
          {"label", m.label},
          {"kind", m.kind},
          {"iso_clause", m.iso_clause},
          {"value_mm", m.value_mm},
          {"geometry", m.geometry},
          {"created_by", m.created_by},
          {"created_at", m.created_at}};
}

nlohmann::json to_json(const TapeMeasurement& t) {
  return {{"scan_id", t.scan_id},       {"name", t.name},
          {"value_mm", t.value_mm},     {"measured_by", t.measured_by},
          {"entered_by", t.entered_by}, {"entered_at", t.entered_at}};
}

struct Archive::Impl {
  fs::path dir;
  int lock_fd = -1;
  mutable Database db;  // const queries prepare statements too
  mutable std::mutex mu;
  std::atomic<uint64_t> revision{0};  // bumped by every change to scans or measurements
  RecoveryReport recovery;

  explicit Impl(Database d) : db(std::move(d)) {}
  ~Impl() {
    if (lock_fd >= 0) ::close(lock_fd);
  }

  fs::path scan_dir(const std::string& id) const { return dir / "scans" / id; }
  fs::path version_dir(const std::string& id, int v) const {
    return v == kRawVersion ? scan_dir(id) / "raw" : scan_dir(id) / ("v" + std::to_string(v));
  }

  Status schema() {
    RETURN_IF_ERROR(
        db.exec("PRAGMA journal_mode=WAL; PRAGMA synchronous=FULL; PRAGMA foreign_keys=ON; PRAGMA secure_delete=ON;"
                "PRAGMA busy_timeout=5000;"));
    RETURN_IF_ERROR(db.exec(R"sql(
      CREATE TABLE IF NOT EXISTS meta(key TEXT PRIMARY KEY, value TEXT NOT NULL);
      CREATE TABLE IF NOT EXISTS customers(
        id TEXT PRIMARY KEY, name TEXT, contact TEXT, created_at TEXT NOT NULL);
      CREATE TABLE IF NOT EXISTS calibrations(
        id TEXT PRIMARY KEY, created_at TEXT NOT NULL, created_by TEXT NOT NULL);
      CREATE TABLE IF NOT EXISTS scans(
        id TEXT PRIMARY KEY,
        customer_id TEXT NOT NULL REFERENCES customers(id) ON DELETE CASCADE,
        operator TEXT NOT NULL,
        calibration_id TEXT REFERENCES calibrations(id),
        status TEXT NOT NULL CHECK(status IN ('running', 'complete', 'failed', 'cancelled')),
        status_reason TEXT NOT NULL DEFAULT '',
        started_at TEXT NOT NULL, finished_at TEXT,
        rig TEXT NOT NULL,
        current_version INTEGER NOT NULL DEFAULT 0);
      CREATE INDEX IF NOT EXISTS scans_customer ON scans(customer_id);
      CREATE INDEX IF NOT EXISTS scans_started ON scans(started_at);
      CREATE TABLE IF NOT EXISTS scan_versions(
        scan_id TEXT NOT NULL REFERENCES scans(id) ON DELETE CASCADE,
        version INTEGER NOT NULL, created_at TEXT NOT NULL, algorithms TEXT NOT NULL, note TEXT NOT NULL,
        PRIMARY KEY(scan_id, version));
      CREATE TABLE IF NOT EXISTS scan_files(
        scan_id TEXT NOT NULL REFERENCES scans(id) ON DELETE CASCADE,
        version INTEGER NOT NULL, name TEXT NOT NULL, bytes INTEGER NOT NULL, blake2b TEXT NOT NULL,
        PRIMARY KEY(scan_id, version, name));
      CREATE TABLE IF NOT EXISTS measurements(
        id INTEGER PRIMARY KEY,
        scan_id TEXT NOT NULL REFERENCES scans(id) ON DELETE CASCADE,
        version INTEGER NOT NULL,
        source TEXT NOT NULL CHECK(source IN ('automatic', 'user')),
        name TEXT NOT NULL, label TEXT NOT NULL, kind TEXT NOT NULL, iso_clause TEXT NOT NULL,
        value_mm REAL NOT NULL, geometry TEXT NOT NULL, created_by TEXT NOT NULL, created_at TEXT NOT NULL);
      CREATE INDEX IF NOT EXISTS measurements_scan ON measurements(scan_id, version);
      CREATE TABLE IF NOT EXISTS audit(
        id INTEGER PRIMARY KEY, at TEXT NOT NULL, actor TEXT NOT NULL, action TEXT NOT NULL,
        target_kind TEXT NOT NULL, target_id TEXT NOT NULL, detail TEXT NOT NULL);
      CREATE INDEX IF NOT EXISTS audit_target ON audit(target_id);
      CREATE TABLE IF NOT EXISTS consents(
        id INTEGER PRIMARY KEY,
        customer_id TEXT NOT NULL REFERENCES customers(id) ON DELETE CASCADE,
        given_at TEXT NOT NULL, recorded_by TEXT NOT NULL, terms TEXT NOT NULL);
      CREATE INDEX IF NOT EXISTS consents_customer ON consents(customer_id);
      CREATE TABLE IF NOT EXISTS tape_measurements(
        scan_id TEXT NOT NULL REFERENCES scans(id) ON DELETE CASCADE,
        name TEXT NOT NULL, value_mm REAL NOT NULL, measured_by TEXT NOT NULL,
        entered_by TEXT NOT NULL, entered_at TEXT NOT NULL,
        PRIMARY KEY(scan_id, name));
    )sql"));
    ASSIGN_OR_RETURN(Statement get, db.prepare("SELECT value FROM meta WHERE key = 'schema'"));
    ASSIGN_OR_RETURN(bool row, get.step());
    if (!row) {
      ASSIGN_OR_RETURN(Statement put, db.prepare("INSERT INTO meta(key, value) VALUES ('schema', ?)"));
      return put.bind(1, std::to_string(kSchemaVersion)).run();
    }
    if (get.text(0) != std::to_string(kSchemaVersion))
      return failed_precondition("archive: its schema version is " + get.text(0) + ", this build reads version " +
                                 std::to_string(kSchemaVersion) + "; use a newer bodyscan");
    return Status::Ok();
  }

  Status log(const std::string& actor, const std::string& action, const std::string& kind, const std::string& target,
             const std::string& detail) {
    ASSIGN_OR_RETURN(Statement st, db.prepare("INSERT INTO audit(at, actor, action, target_kind, target_id, detail) "
                                              "VALUES (?, ?, ?, ?, ?, ?)"));
    return st.bind(1, now_iso()).bind(2, actor).bind(3, action).bind(4, kind).bind(5, target).bind(6, detail).run();
  }

  StatusOr<std::vector<ArchivedFile>> files(const std::string& scan, int version) const {
    ASSIGN_OR_RETURN(Statement st,
                     db.prepare("SELECT name, bytes, blake2b FROM scan_files WHERE scan_id = ? AND version = ? "
                                "ORDER BY name"));
    st.bind(1, scan).bind(2, version);
    std::vector<ArchivedFile> out;
    for (;;) {
      ASSIGN_OR_RETURN(bool row, st.step());
      if (!row) break;
      out.push_back({st.text(0), static_cast<uint64_t>(st.integer(1)), st.text(2)});
    }
    return out;
  }

  StatusOr<ScanRecord> record(const std::string& id) const {
    ASSIGN_OR_RETURN(Statement st,
                     db.prepare("SELECT id, customer_id, operator, IFNULL(calibration_id, ''), status, "
                                "status_reason, started_at, IFNULL(finished_at, ''), rig, current_version "
                                "FROM scans WHERE id = ?"));
    st.bind(1, id);
    ASSIGN_OR_RETURN(bool row, st.step());
    if (!row) return not_found("archive: no scan '" + id + "'");
    ScanRecord r;
    r.id = st.text(0), r.customer_id = st.text(1), r.operator_name = st.text(2), r.calibration_id = st.text(3);
    r.status = parse_status(st.text(4));
    r.status_reason = st.text(5), r.started_at = st.text(6), r.finished_at = st.text(7);
    r.rig = parse_json(st.text(8));
    r.current_version = static_cast<int>(st.integer(9));
    ASSIGN_OR_RETURN(Statement vs, db.prepare("SELECT version, created_at, algorithms, note FROM scan_versions "
                                              "WHERE scan_id = ? ORDER BY version"));
    vs.bind(1, id);
    for (;;) {
      ASSIGN_OR_RETURN(bool more, vs.step());
      if (!more) break;
      ScanVersion v;
      v.version = static_cast<int>(vs.integer(0));
      v.created_at = vs.text(1);
      v.algorithms = parse_json(vs.text(2));
      v.note = vs.text(3);
      ASSIGN_OR_RETURN(v.files, files(id, v.version));
      r.versions.push_back(std::move(v));
    }
    ASSIGN_OR_RETURN(r.raw, files(id, kRawVersion));
    return r;
  }

  static nlohmann::json manifest(const ScanRecord& r) {
    nlohmann::json versions = nlohmann::json::array();
    for (const ScanVersion& v : r.versions) {
      nlohmann::json files = nlohmann::json::array();
      for (const ArchivedFile& f : v.files) files.push_back(file_json(f));
      versions.push_back({{"version", v.version},
                          {"created_at", v.created_at},
                          {"algorithms", v.algorithms},
                          {"note", v.note},
                          {"files", files}});
    }
    nlohmann::json raw = nlohmann::json::array();
    for (const ArchivedFile& f : r.raw) raw.push_back(file_json(f));
    return {{"schema", "bodyscan.scan-manifest/1"},
            {"scan", r.id},
            {"customer", r.customer_id},
            {"operator", r.operator_name},
            {"calibration", r.calibration_id},
            {"status", to_string(r.status)},
            {"started_at", r.started_at},
            {"finished_at", r.finished_at},
            {"current_version", r.current_version},
            {"rig", r.rig},
            {"raw", raw},
            {"versions", versions}};
  }

  // The manifest as the index describes the scan (inside a transaction: as it
  // will be once committed).
  Status write_manifest(const std::string& id) {
    ASSIGN_OR_RETURN(ScanRecord r, record(id));
    return write_file_atomically((scan_dir(id) / "manifest.json").string(), manifest(r).dump(1));
  }

  // Writes files into `folder` (each whole or not at all) and lists them.
  StatusOr<std::vector<ArchivedFile>> put_files(const fs::path& folder,
                                                const std::map<std::string, std::string>& files) {
    RETURN_IF_ERROR(make_dirs(folder));
    std::vector<ArchivedFile> out;
    for (const auto& [name, bytes] : files) {
      if (!safe_name(name)) return invalid_argument("archive: '" + name + "' is not a file name the archive accepts");
      RETURN_IF_ERROR(write_file_atomically((folder / name).string(), bytes));
      out.push_back({name, bytes.size(), blake2b_hex(bytes)});
    }
    sync_dir(folder.parent_path());
    return out;
  }

  Status insert_files(const std::string& scan, int version, const std::vector<ArchivedFile>& files) {
    ASSIGN_OR_RETURN(Statement st,
                     db.prepare("INSERT OR REPLACE INTO scan_files(scan_id, version, name, bytes, blake2b) "
                                "VALUES (?, ?, ?, ?, ?)"));
    for (const ArchivedFile& f : files) {
      st.bind(1, scan).bind(2, version).bind(3, f.name).bind(4, static_cast<int64_t>(f.bytes)).bind(5, f.blake2b);
      RETURN_IF_ERROR(st.run());
      st.reset();
    }
    return Status::Ok();
  }

  Status insert_measurement(const MeasurementRecord& m, int64_t* id) {
    ASSIGN_OR_RETURN(
        Statement st,
        db.prepare("INSERT INTO measurements(scan_id, version, source, name, label, kind, iso_clause, "
                   "value_mm, geometry, created_by, created_at) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)"));
    st.bind(1, m.scan_id).bind(2, m.version).bind(3, m.source).bind(4, m.name).bind(5, m.label).bind(6, m.kind);
    st.bind(7, m.iso_clause).bind(8, m.value_mm).bind(9, m.geometry.dump()).bind(10, m.created_by);
    st.bind(11, m.created_at.empty() ? now_iso() : m.created_at);
    RETURN_IF_ERROR(st.run());
    if (id) *id = sqlite3_last_insert_rowid(db.handle());
    return Status::Ok();
  }

  StatusOr<std::vector<std::string>> ids(const std::string& sql, const std::string& arg = "") {
    ASSIGN_OR_RETURN(Statement st, db.prepare(sql));
    if (!arg.empty()) st.bind(1, arg);
    std::vector<std::string> out;
    for (;;) {
      ASSIGN_OR_RETURN(bool row, st.step());
      if (!row) break;
      out.push_back(st.text(0));
    }
    return out;
  }

  // Moves a folder out of the way, then removes it; a crash in between leaves
  // it in trash/, which the next open clears.
  void discard(const fs::path& folder) {
    std::error_code ec;
    if (!fs::exists(folder, ec)) return;
    const fs::path trash = dir / "trash" / (folder.filename().string() + "-" + random_hex(4));
    fs::create_directories(trash.parent_path(), ec);
    fs::rename(folder, trash, ec);
    fs::remove_all(ec ? folder : trash, ec);
    sync_dir(folder.parent_path());
  }

  Status recover() {
    std::error_code ec;
    // Temporary files of interrupted writes, and anything in the trash.
    for (const char* top : {"scans", "calibrations"}) {
      if (!fs::exists(dir / top, ec)) continue;
      std::vector<fs::path> temps;
      for (auto it = fs::recursive_directory_iterator(dir / top, ec); !ec && it != fs::recursive_directory_iterator();
           it.increment(ec))
        if (it->path().filename().string().find(".tmp-") != std::string::npos) temps.push_back(it->path());
      for (const fs::path& p : temps) recovery.temp_files_removed += fs::remove(p, ec) ? 1 : 0;
    }
    fs::remove_all(dir / "trash", ec);

    // Scans left running: failed, with the reason, and nothing half-written kept.
    ASSIGN_OR_RETURN(std::vector<std::string> running, ids("SELECT id FROM scans WHERE status = 'running'"));
    for (const std::string& id : running) {
      ASSIGN_OR_RETURN(Transaction tx, Transaction::begin(db));
      for (const char* sql : {"DELETE FROM scan_files WHERE scan_id = ?", "DELETE FROM scan_versions WHERE scan_id = ?",
                              "DELETE FROM measurements WHERE scan_id = ?"}) {
        ASSIGN_OR_RETURN(Statement st, db.prepare(sql));
        RETURN_IF_ERROR(st.bind(1, id).run());
      }
      ASSIGN_OR_RETURN(Statement st,
                       db.prepare("UPDATE scans SET status = 'failed', status_reason = ?, finished_at = ?, "
                                  "current_version = 0 WHERE id = ?"));
      RETURN_IF_ERROR(st.bind(1, kInterrupted).bind(2, now_iso()).bind(3, id).run());
      RETURN_IF_ERROR(log("system", "recover", "scan", id, kInterrupted));
      RETURN_IF_ERROR(tx.commit());
      discard(scan_dir(id));
      recovery.scans_failed.push_back(id);
    }

    // Folders the index does not know; result versions it does not own.
    ASSIGN_OR_RETURN(std::vector<std::string> known, ids("SELECT id FROM scans"));
    const std::set<std::string> known_set(known.begin(), known.end());
    if (fs::exists(dir / "scans", ec)) {
      std::vector<fs::path> folders;
      for (const auto& e : fs::directory_iterator(dir / "scans", ec)) folders.push_back(e.path());
      for (const fs::path& f : folders)
        if (!known_set.count(f.filename().string())) discard(f), ++recovery.orphans_removed;
    }
    for (const std::string& id : known) {
      ASSIGN_OR_RETURN(ScanRecord r, record(id));
      if (r.status != ScanStatus::kComplete) {
        if (fs::exists(scan_dir(id), ec)) discard(scan_dir(id));
        continue;
      }
      std::set<std::string> owned = {"raw", "manifest.json"};
      for (const ScanVersion& v : r.versions) owned.insert("v" + std::to_string(v.version));
      std::vector<fs::path> extra;
      for (const auto& e : fs::directory_iterator(scan_dir(id), ec))
        if (!owned.count(e.path().filename().string())) extra.push_back(e.path());
      for (const fs::path& p : extra) discard(p), ++recovery.versions_removed;
      const std::string want = manifest(r).dump(1);
      auto have = slurp(scan_dir(id) / "manifest.json");
      if (!have.ok() || *have != want)
        RETURN_IF_ERROR(write_file_atomically((scan_dir(id) / "manifest.json").string(), want));
    }
    ASSIGN_OR_RETURN(std::vector<std::string> cals, ids("SELECT id FROM calibrations"));
    const std::set<std::string> cal_set(cals.begin(), cals.end());
    if (fs::exists(dir / "calibrations", ec)) {
      std::vector<fs::path> folders;
      for (const auto& e : fs::directory_iterator(dir / "calibrations", ec)) folders.push_back(e.path());
      for (const fs::path& f : folders)
        if (!cal_set.count(f.filename().string())) discard(f), ++recovery.orphans_removed;
    }
    return Status::Ok();
  }
};

Archive::Archive(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Archive::~Archive() = default;
const RecoveryReport& Archive::recovery() const { return impl_->recovery; }
std::string Archive::dir() const { return impl_->dir.string(); }

StatusOr<std::unique_ptr<Archive>> Archive::open(const std::string& dir_in) {
  if (sodium_init() < 0) return internal_error("archive: libsodium failed to start");
  const fs::path dir = fs::absolute(dir_in);
  RETURN_IF_ERROR(make_dirs(dir));
  // People's names and bodies: the folder is its owner's alone, whatever the
  // umask made of it (a copy made with rsync -a or cp -a keeps that too).
  std::error_code perm_ec;
  fs::permissions(dir, fs::perms::owner_all, fs::perm_options::replace, perm_ec);
  if (perm_ec) return io_error("archive: cannot make " + dir.string() + " private: " + perm_ec.message());
  RETURN_IF_ERROR(make_dirs(dir / "scans"));
  RETURN_IF_ERROR(make_dirs(dir / "calibrations"));
  // Created private before SQLite opens it (SQLite gives its -wal and -shm the
  // database's mode).
  const std::string db_path = (dir / "archive.db").string();
  if (const int db_fd = ::open(db_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600); db_fd >= 0) ::close(db_fd);
  const std::string lock_path = (dir / "archive.lock").string();
  const int fd = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  if (fd < 0) return io_error("archive: cannot open " + lock_path + ": " + std::strerror(errno));
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd);
    return unavailable("archive: " + dir.string() + " is in use by another bodyscan process");
  }
  auto db = Database::open(db_path);
  if (!db.ok()) {
    ::close(fd);
    return db.status();
  }
  auto impl = std::make_unique<Impl>(std::move(*db));
  impl->dir = dir;
  impl->lock_fd = fd;
  RETURN_IF_ERROR(impl->schema());
  RETURN_IF_ERROR(impl->recover());
  return std::unique_ptr<Archive>(new Archive(std::move(impl)));
}

// --- customers ---------------------------------------------------------------

StatusOr<Customer> Archive::add_customer(const std::optional<std::string>& name,
                                         const std::optional<std::string>& contact, const std::string& actor) {
  std::lock_guard lock(impl_->mu);
  Customer c{"c_" + random_hex(8), name, contact, now_iso(), std::nullopt};
  ASSIGN_OR_RETURN(Transaction tx, Transaction::begin(impl_->db));
  ASSIGN_OR_RETURN(Statement st,
                   impl_->db.prepare("INSERT INTO customers(id, name, contact, created_at) VALUES (?, ?, ?, ?)"));
  RETURN_IF_ERROR(st.bind(1, c.id).bind(2, c.name).bind(3, c.contact).bind(4, c.created_at).run());
  RETURN_IF_ERROR(impl_->log(actor, "add customer", "customer", c.id, ""));
  RETURN_IF_ERROR(tx.commit());
  return c;
}

namespace {
// A search's words, at whitespace; a search of more words than this is refused.
constexpr size_t kMaxSearchWords = 8;

StatusOr<std::vector<std::string>> search_words(const std::string& text) {
  std::vector<std::string> words;
  size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    size_t j = i;
    while (j < text.size() && !std::isspace(static_cast<unsigned char>(text[j]))) ++j;
    if (j > i) words.push_back(text.substr(i, j - i));
    i = j;
  }
  if (words.size() > kMaxSearchWords)
    return invalid_argument("archive: search with at most " + std::to_string(kMaxSearchWords) + " words");
  return words;
}

// SQL true when every one of `n` words (bound from parameter `first` on) occurs
// in `haystack`, in any order and case (ASCII).
std::string all_words_in(const std::string& haystack, int first, size_t n) {
  std::string sql = "(1";
  for (size_t k = 0; k < n; ++k)
    sql += " AND instr(lower(" + haystack + "), lower(?" + std::to_string(first + static_cast<int>(k)) + "))";
  return sql + ")";
}

// The customer's columns and their latest consent's, as read_customer reads them.
constexpr const char* kCustomerColumns =
    "SELECT c.id, c.name, c.contact, c.created_at, k.given_at, k.recorded_by, k.terms FROM customers c "
    "LEFT JOIN consents k ON k.id = (SELECT max(id) FROM consents WHERE customer_id = c.id) ";

Customer read_customer(const Statement& st) {
  Customer c{st.text(0), st.maybe_text(1), st.maybe_text(2), st.text(3), std::nullopt};
  if (std::optional<std::string> at = st.maybe_text(4)) c.consent = Consent{*at, st.text(5), st.text(6)};
  return c;
}
}  // namespace

StatusOr<Consent> Archive::record_consent(const std::string& customer_id, const std::string& terms,
                                          const std::string& actor) {
  if (terms.empty()) return invalid_argument("archive: a consent needs the terms the customer agreed to");
  std::lock_guard lock(impl_->mu);
  Consent k{now_iso(), actor, terms};
  ASSIGN_OR_RETURN(Transaction tx, Transaction::begin(impl_->db));
  ASSIGN_OR_RETURN(std::vector<std::string> found, impl_->ids("SELECT id FROM customers WHERE id = ?", customer_id));
  if (found.empty()) return not_found("archive: no customer '" + customer_id + "'");
  ASSIGN_OR_RETURN(Statement st, impl_->db.prepare("INSERT INTO consents(customer_id, given_at, recorded_by, terms) "
                                                   "VALUES (?, ?, ?, ?)"));
  RETURN_IF_ERROR(st.bind(1, customer_id).bind(2, k.given_at).bind(3, k.recorded_by).bind(4, k.terms).run());
  RETURN_IF_ERROR(impl_->log(actor, "record consent", "customer", customer_id, ""));
  RETURN_IF_ERROR(tx.commit());
  return k;
}

StatusOr<Customer> Archive::customer(const std::string& id) const {
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(Statement st, impl_->db.prepare(std::string(kCustomerColumns) + "WHERE c.id = ?"));
  st.bind(1, id);
  ASSIGN_OR_RETURN(bool row, st.step());
  if (!row) return not_found("archive: no customer '" + id + "'");
  return read_customer(st);
}

StatusOr<std::vector<Customer>> Archive::customers(const std::string& text) const {
  ASSIGN_OR_RETURN(const std::vector<std::string> words, search_words(text));
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(Statement st,
                   impl_->db.prepare(std::string(kCustomerColumns) + "WHERE " +
                                     all_words_in("c.id || ' ' || IFNULL(c.name, '') || ' ' || IFNULL(c.contact, '')",
                                                  1, words.size()) +
                                     " ORDER BY c.created_at DESC"));
  for (size_t k = 0; k < words.size(); ++k) st.bind(static_cast<int>(k) + 1, words[k]);
  std::vector<Customer> out;
  for (;;) {
    ASSIGN_OR_RETURN(bool row, st.step());
    if (!row) break;
    out.push_back(read_customer(st));
  }
  return out;
}

Status Archive::delete_customer(const std::string& id, const std::string& actor) {
  impl_->revision.fetch_add(1);
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(std::vector<std::string> scan_ids, impl_->ids("SELECT id FROM scans WHERE customer_id = ?", id));
  {
    ASSIGN_OR_RETURN(Transaction tx, Transaction::begin(impl_->db));
    ASSIGN_OR_RETURN(Statement audit, impl_->db.prepare("DELETE FROM audit WHERE target_id = ?"));
    for (const std::string& t : scan_ids) {
      RETURN_IF_ERROR(audit.bind(1, t).run());
      audit.reset();
    }
    RETURN_IF_ERROR(audit.bind(1, id).run());
    ASSIGN_OR_RETURN(Statement del, impl_->db.prepare("DELETE FROM customers WHERE id = ?"));
    RETURN_IF_ERROR(del.bind(1, id).run());
    if (sqlite3_changes(impl_->db.handle()) == 0) return not_found("archive: no customer '" + id + "'");
    RETURN_IF_ERROR(impl_->log(actor, "erase customer", "customer", "",
                               std::to_string(scan_ids.size()) + " scan(s) and their files erased"));
    RETURN_IF_ERROR(tx.commit());
  }
  for (const std::string& s : scan_ids) impl_->discard(impl_->scan_dir(s));
  // Nothing of theirs may linger in the write-ahead log either.
  return impl_->db.exec("PRAGMA wal_checkpoint(TRUNCATE)");
}

// --- calibrations ------------------------------------------------------------

StatusOr<std::string> Archive::add_calibration(const nlohmann::json& rig, const nlohmann::json& calibration,
                                               const std::string& actor) {
  const std::string id = new_id('k');
  const fs::path folder = impl_->dir / "calibrations" / id;
  RETURN_IF_ERROR(make_dirs(folder));
  RETURN_IF_ERROR(write_file_atomically((folder / "rig.json").string(), rig.dump(1)));
  RETURN_IF_ERROR(write_file_atomically((folder / "calibration.json").string(), calibration.dump(1)));
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(Transaction tx, Transaction::begin(impl_->db));
  ASSIGN_OR_RETURN(Statement st,
                   impl_->db.prepare("INSERT INTO calibrations(id, created_at, created_by) VALUES (?, ?, ?)"));
  RETURN_IF_ERROR(st.bind(1, id).bind(2, now_iso()).bind(3, actor).run());
  RETURN_IF_ERROR(impl_->log(actor, "calibrate", "calibration", id, ""));
  RETURN_IF_ERROR(tx.commit());
  return id;
}

StatusOr<nlohmann::json> Archive::calibration(const std::string& id) const {
  if (!safe_name(id)) return not_found("archive: no calibration '" + id + "'");
  {
    std::lock_guard lock(impl_->mu);
    ASSIGN_OR_RETURN(std::vector<std::string> found, impl_->ids("SELECT id FROM calibrations WHERE id = ?", id));
    if (found.empty()) return not_found("archive: no calibration '" + id + "'");
  }
  const fs::path folder = impl_->dir / "calibrations" / id;
  ASSIGN_OR_RETURN(std::string rig, slurp(folder / "rig.json"));
  ASSIGN_OR_RETURN(std::string cal, slurp(folder / "calibration.json"));
  return nlohmann::json{{"id", id}, {"rig", parse_json(rig)}, {"calibration", parse_json(cal)}};
}

// --- scans -------------------------------------------------------------------

StatusOr<std::string> Archive::begin_scan(const std::string& customer_id, const std::string& operator_name,
                                          const nlohmann::json& rig, const std::string& calibration_id) {
  impl_->revision.fetch_add(1);
  std::lock_guard lock(impl_->mu);
  const std::string id = new_id('s');
  ASSIGN_OR_RETURN(Transaction tx, Transaction::begin(impl_->db));
  ASSIGN_OR_RETURN(
      Statement st,
      impl_->db.prepare("INSERT INTO scans(id, customer_id, operator, calibration_id, status, started_at, rig) "
                        "VALUES (?, ?, ?, ?, 'running', ?, ?)"));
  st.bind(1, id).bind(2, customer_id).bind(3, operator_name);
  if (calibration_id.empty())
    st.bind_null(4);
  else
    st.bind(4, calibration_id);
  st.bind(5, now_iso()).bind(6, rig.dump());
  const Status s = st.run();
  if (!s.ok()) {
    if (s.code() == StatusCode::kInvalidArgument)
      return not_found("archive: no customer '" + customer_id + "'" +
                       (calibration_id.empty() ? "" : " or calibration '" + calibration_id + "'"));
    return s;
  }
  RETURN_IF_ERROR(impl_->log(operator_name, "start scan", "scan", id, "customer " + customer_id));
  RETURN_IF_ERROR(tx.commit());
  return id;
}

Status Archive::put_raw(const std::string& scan_id, const std::string& name, std::string_view bytes) {
  impl_->revision.fetch_add(1);
  {
    std::lock_guard lock(impl_->mu);
    ASSIGN_OR_RETURN(ScanRecord r, impl_->record(scan_id));
    if (r.status != ScanStatus::kRunning) return failed_precondition("archive: scan '" + scan_id + "' is not running");
  }
  ASSIGN_OR_RETURN(std::vector<ArchivedFile> f,
                   impl_->put_files(impl_->version_dir(scan_id, kRawVersion), {{name, std::string(bytes)}}));
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(Transaction tx, Transaction::begin(impl_->db));
  RETURN_IF_ERROR(impl_->insert_files(scan_id, kRawVersion, f));
  return tx.commit();
}

Status Archive::set_scan_calibration(const std::string& scan_id, const std::string& calibration_id) {
  impl_->revision.fetch_add(1);
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(ScanRecord r, impl_->record(scan_id));
  if (r.status != ScanStatus::kRunning) return failed_precondition("archive: scan '" + scan_id + "' is not running");
  ASSIGN_OR_RETURN(Statement st, impl_->db.prepare("UPDATE scans SET calibration_id = ? WHERE id = ?"));
  const Status s = st.bind(1, calibration_id).bind(2, scan_id).run();
  if (s.code() == StatusCode::kInvalidArgument) return not_found("archive: no calibration '" + calibration_id + "'");
  return s;
}

Status Archive::complete_scan(const std::string& scan_id, const ScanResults& results) {
  impl_->revision.fetch_add(1);
  {
    std::lock_guard lock(impl_->mu);
    ASSIGN_OR_RETURN(ScanRecord r, impl_->record(scan_id));
    if (r.status != ScanStatus::kRunning) return failed_precondition("archive: scan '" + scan_id + "' is not running");
  }
  // The files first, outside the lock (only this scan's writer touches its folder).
  ASSIGN_OR_RETURN(std::vector<ArchivedFile> files, impl_->put_files(impl_->version_dir(scan_id, 1), results.files));
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(Transaction tx, Transaction::begin(impl_->db));
  RETURN_IF_ERROR(impl_->insert_files(scan_id, 1, files));
  ASSIGN_OR_RETURN(
      Statement v,
      impl_->db.prepare(
          "INSERT INTO scan_versions(scan_id, version, created_at, algorithms, note) VALUES (?, 1, ?, ?, ?)"));
  RETURN_IF_ERROR(v.bind(1, scan_id).bind(2, now_iso()).bind(3, results.algorithms.dump()).bind(4, results.note).run());
  for (MeasurementRecord m : results.measurements) {
    m.scan_id = scan_id, m.version = 1, m.source = "automatic";
    if (m.created_by.empty()) m.created_by = "system";
    RETURN_IF_ERROR(impl_->insert_measurement(m, nullptr));
  }
  ASSIGN_OR_RETURN(Statement st,
                   impl_->db.prepare("UPDATE scans SET status = 'complete', status_reason = '', finished_at = ?, "
                                     "current_version = 1 WHERE id = ?"));
  RETURN_IF_ERROR(st.bind(1, now_iso()).bind(2, scan_id).run());
  RETURN_IF_ERROR(impl_->log("system", "complete scan", "scan", scan_id, std::to_string(files.size()) + " files"));
  // The manifest, as the index will say once this commits, then the commit.
  RETURN_IF_ERROR(impl_->write_manifest(scan_id));
  return tx.commit();
}

Status Archive::end_scan(const std::string& scan_id, ScanStatus status, const std::string& reason) {
  impl_->revision.fetch_add(1);
  if (status != ScanStatus::kFailed && status != ScanStatus::kCancelled)
    return invalid_argument("archive: a scan ends failed or cancelled here; complete_scan completes it");
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(ScanRecord r, impl_->record(scan_id));
  if (r.status != ScanStatus::kRunning) return failed_precondition("archive: scan '" + scan_id + "' is not running");
  {
    ASSIGN_OR_RETURN(Transaction tx, Transaction::begin(impl_->db));
    ASSIGN_OR_RETURN(Statement files, impl_->db.prepare("DELETE FROM scan_files WHERE scan_id = ?"));
    RETURN_IF_ERROR(files.bind(1, scan_id).run());
    ASSIGN_OR_RETURN(Statement st,
                     impl_->db.prepare("UPDATE scans SET status = ?, status_reason = ?, finished_at = ? WHERE id = ?"));
    RETURN_IF_ERROR(st.bind(1, to_string(status)).bind(2, reason).bind(3, now_iso()).bind(4, scan_id).run());
    RETURN_IF_ERROR(impl_->log("system", status == ScanStatus::kFailed ? "scan failed" : "scan cancelled", "scan",
                               scan_id, reason));
    RETURN_IF_ERROR(tx.commit());
  }
  impl_->discard(impl_->scan_dir(scan_id));
  return Status::Ok();
}

StatusOr<int> Archive::add_version(const std::string& scan_id, const ScanResults& results, const std::string& actor) {
  impl_->revision.fetch_add(1);
  int version = 0;
  {
    std::lock_guard lock(impl_->mu);
    ASSIGN_OR_RETURN(ScanRecord r, impl_->record(scan_id));
    if (r.status != ScanStatus::kComplete)
      return failed_precondition("archive: scan '" + scan_id + "' has no results to reprocess");
    version = r.versions.empty() ? 1 : r.versions.back().version + 1;
  }
  const fs::path folder = impl_->version_dir(scan_id, version);
  auto files = impl_->put_files(folder, results.files);
  if (!files.ok()) {
    impl_->discard(folder);
    return files.status();
  }
  std::lock_guard lock(impl_->mu);
  Status s = [&]() -> Status {
    ASSIGN_OR_RETURN(Transaction tx, Transaction::begin(impl_->db));
    RETURN_IF_ERROR(impl_->insert_files(scan_id, version, *files));
    ASSIGN_OR_RETURN(
        Statement v,
        impl_->db.prepare(
            "INSERT INTO scan_versions(scan_id, version, created_at, algorithms, note) VALUES (?, ?, ?, ?, ?)"));
    RETURN_IF_ERROR(v.bind(1, scan_id)
                        .bind(2, version)
                        .bind(3, now_iso())
                        .bind(4, results.algorithms.dump())
                        .bind(5, results.note)
                        .run());
    for (MeasurementRecord m : results.measurements) {
      m.scan_id = scan_id, m.version = version, m.source = "automatic";
      if (m.created_by.empty()) m.created_by = actor;
      RETURN_IF_ERROR(impl_->insert_measurement(m, nullptr));
    }
    ASSIGN_OR_RETURN(Statement st, impl_->db.prepare("UPDATE scans SET current_version = ? WHERE id = ?"));
    RETURN_IF_ERROR(st.bind(1, version).bind(2, scan_id).run());
    RETURN_IF_ERROR(impl_->log(actor, "reprocess scan", "scan", scan_id, "version " + std::to_string(version)));
    RETURN_IF_ERROR(impl_->write_manifest(scan_id));
    return tx.commit();
  }();
  if (!s.ok()) {
    impl_->discard(folder);
    impl_->write_manifest(scan_id);  // back to what the index says
    return s;
  }
  return version;
}

Status Archive::delete_scan(const std::string& id, const std::string& actor) {
  impl_->revision.fetch_add(1);
  std::lock_guard lock(impl_->mu);
  {
    ASSIGN_OR_RETURN(Transaction tx, Transaction::begin(impl_->db));
    ASSIGN_OR_RETURN(Statement st, impl_->db.prepare("DELETE FROM scans WHERE id = ?"));
    RETURN_IF_ERROR(st.bind(1, id).run());
    if (sqlite3_changes(impl_->db.handle()) == 0) return not_found("archive: no scan '" + id + "'");
    RETURN_IF_ERROR(impl_->log(actor, "delete scan", "scan", id, ""));
    RETURN_IF_ERROR(tx.commit());
  }
  impl_->discard(impl_->scan_dir(id));
  // Nothing of it may linger in the write-ahead log either.
  return impl_->db.exec("PRAGMA wal_checkpoint(TRUNCATE)");
}

StatusOr<ScanRecord> Archive::scan(const std::string& id) const {
  std::lock_guard lock(impl_->mu);
  return impl_->record(id);
}

StatusOr<std::vector<ScanRecord>> Archive::scans(const ScanQuery& q) const {
  ASSIGN_OR_RETURN(const std::vector<std::string> words, search_words(q.text));
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(
      Statement st,
      impl_->db.prepare(
          "SELECT s.id FROM scans s JOIN customers c ON c.id = s.customer_id "
          "WHERE (?1 = '' OR s.customer_id = ?1) AND " +
          all_words_in("s.id || ' ' || s.customer_id || ' ' || IFNULL(c.name, '') || ' ' || "
                       "IFNULL(c.contact, '') || ' ' || s.operator",
                       5, words.size()) +
          " AND (?2 = '' OR s.started_at >= ?2) AND (?3 = '' OR substr(s.started_at, 1, length(?3)) <= ?3) "
          "ORDER BY s.started_at DESC, s.id DESC LIMIT ?4"));
  st.bind(1, q.customer_id).bind(2, q.from).bind(3, q.to).bind(4, q.limit);
  for (size_t k = 0; k < words.size(); ++k) st.bind(static_cast<int>(k) + 5, words[k]);
  std::vector<std::string> found;
  for (;;) {
    ASSIGN_OR_RETURN(bool row, st.step());
    if (!row) break;
    found.push_back(st.text(0));
  }
  std::vector<ScanRecord> out;
  for (const std::string& id : found) {
    ASSIGN_OR_RETURN(ScanRecord r, impl_->record(id));
    out.push_back(std::move(r));
  }
  return out;
}

StatusOr<std::string> Archive::file_path(const std::string& scan_id, int version, const std::string& name) const {
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(ScanRecord r, impl_->record(scan_id));
  const int v = version == 0 ? r.current_version : version;
  const std::vector<ArchivedFile>* list = &r.raw;
  if (v != kRawVersion) {
    list = nullptr;
    for (const ScanVersion& sv : r.versions)
      if (sv.version == v) list = &sv.files;
  }
  if (list)
    for (const ArchivedFile& f : *list)
      if (f.name == name) return (impl_->version_dir(scan_id, v) / name).string();
  return not_found("archive: scan '" + scan_id + "' has no file '" + name + "'" +
                   (v == kRawVersion ? " in its raw data" : " in version " + std::to_string(v)));
}

// --- measurements ------------------------------------------------------------

uint64_t Archive::revision() const { return impl_->revision.load(); }

StatusOr<std::vector<MeasurementRecord>> Archive::measurements(const std::string& scan_id, int version) const {
  std::vector<MeasurementRecord> out;
  std::vector<std::string> geometry;  // parsed after the lock is let go: it is most of the work
  {
    std::lock_guard lock(impl_->mu);
    ASSIGN_OR_RETURN(ScanRecord r, impl_->record(scan_id));
    const int v = version == 0 ? r.current_version : version;
    ASSIGN_OR_RETURN(
        Statement st,
        impl_->db.prepare("SELECT id, scan_id, version, source, name, label, kind, iso_clause, value_mm, geometry, "
                          "created_by, created_at FROM measurements WHERE scan_id = ? AND "
                          "(version = ? OR source = 'user') ORDER BY source, id"));
    st.bind(1, scan_id).bind(2, v);
    for (;;) {
      ASSIGN_OR_RETURN(bool row, st.step());
      if (!row) break;
      MeasurementRecord m;
      m.id = st.integer(0), m.scan_id = st.text(1), m.version = static_cast<int>(st.integer(2));
      m.source = st.text(3), m.name = st.text(4), m.label = st.text(5), m.kind = st.text(6), m.iso_clause = st.text(7);
      m.value_mm = st.real(8);
      geometry.push_back(st.text(9));
      m.created_by = st.text(10), m.created_at = st.text(11);
      out.push_back(std::move(m));
    }
  }
  for (size_t i = 0; i < out.size(); ++i) out[i].geometry = parse_json(geometry[i]);
  return out;
}

StatusOr<int64_t> Archive::save_measurement(const MeasurementRecord& in, const std::string& actor) {
  impl_->revision.fetch_add(1);
  if (in.name.empty()) return invalid_argument("archive: a saved measurement needs a name");
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(ScanRecord r, impl_->record(in.scan_id));
  if (r.status != ScanStatus::kComplete)
    return failed_precondition("archive: scan '" + in.scan_id + "' has no surface to measure");
  MeasurementRecord m = in;
  m.source = "user", m.version = r.current_version, m.created_by = actor, m.created_at = now_iso();
  ASSIGN_OR_RETURN(Transaction tx, Transaction::begin(impl_->db));
  int64_t id = 0;
  RETURN_IF_ERROR(impl_->insert_measurement(m, &id));
  RETURN_IF_ERROR(impl_->log(actor, "save measurement", "scan", m.scan_id, m.name));
  RETURN_IF_ERROR(tx.commit());
  return id;
}

Status Archive::delete_measurement(const std::string& scan_id, int64_t id, const std::string& actor) {
  impl_->revision.fetch_add(1);
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(Transaction tx, Transaction::begin(impl_->db));
  ASSIGN_OR_RETURN(Statement st,
                   impl_->db.prepare("DELETE FROM measurements WHERE id = ? AND scan_id = ? AND source = 'user'"));
  RETURN_IF_ERROR(st.bind(1, id).bind(2, scan_id).run());
  if (sqlite3_changes(impl_->db.handle()) == 0)
    return not_found("archive: scan '" + scan_id + "' has no saved measurement " + std::to_string(id));
  RETURN_IF_ERROR(impl_->log(actor, "delete measurement", "scan", scan_id, std::to_string(id)));
  return tx.commit();
}

// --- tape measurements -------------------------------------------------------

StatusOr<std::vector<TapeMeasurement>> Archive::tape_measurements(const std::string& scan_id) const {
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(Statement st,
                   impl_->db.prepare("SELECT t.scan_id, s.customer_id, t.name, t.value_mm, t.measured_by, "
                                     "t.entered_by, t.entered_at FROM tape_measurements t JOIN scans s "
                                     "ON s.id = t.scan_id WHERE ?1 = '' OR t.scan_id = ?1 "
                                     "ORDER BY t.entered_at, t.scan_id, t.name"));
  st.bind(1, scan_id);
  std::vector<TapeMeasurement> out;
  for (;;) {
    ASSIGN_OR_RETURN(bool row, st.step());
    if (!row) break;
    out.push_back({st.text(0), st.text(1), st.text(2), st.real(3), st.text(4), st.text(5), st.text(6)});
  }
  return out;
}

Status Archive::put_tape_measurement(const TapeMeasurement& t, const std::string& actor) {
  impl_->revision.fetch_add(1);
  if (!(t.value_mm >= 1 && t.value_mm <= 3000))
    return invalid_argument("archive: a tape measurement is between 1 mm and 3 m");
  if (t.measured_by.empty() || t.measured_by.size() > 200)
    return invalid_argument("archive: a tape measurement needs who took it (up to 200 characters)");
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(ScanRecord r, impl_->record(t.scan_id));
  if (r.status != ScanStatus::kComplete)
    return failed_precondition("archive: scan '" + t.scan_id + "' has no measurements to compare with");
  ASSIGN_OR_RETURN(Statement known, impl_->db.prepare("SELECT 1 FROM measurements WHERE scan_id = ? AND version = ? "
                                                      "AND source = 'automatic' AND name = ?"));
  known.bind(1, t.scan_id).bind(2, r.current_version).bind(3, t.name);
  ASSIGN_OR_RETURN(bool found, known.step());
  if (!found) return not_found("archive: scan '" + t.scan_id + "' has no automatic measurement '" + t.name + "'");
  ASSIGN_OR_RETURN(Transaction tx, Transaction::begin(impl_->db));
  ASSIGN_OR_RETURN(Statement st, impl_->db.prepare("INSERT OR REPLACE INTO tape_measurements(scan_id, name, value_mm, "
                                                   "measured_by, entered_by, entered_at) VALUES (?, ?, ?, ?, ?, ?)"));
  RETURN_IF_ERROR(st.bind(1, t.scan_id)
                      .bind(2, t.name)
                      .bind(3, t.value_mm)
                      .bind(4, t.measured_by)
                      .bind(5, actor)
                      .bind(6, now_iso())
                      .run());
  char detail[64];
  std::snprintf(detail, sizeof detail, " %.1f mm", t.value_mm);
  RETURN_IF_ERROR(
      impl_->log(actor, "enter tape measurement", "scan", t.scan_id, t.name + detail + " by " + t.measured_by));
  return tx.commit();
}

Status Archive::delete_tape_measurement(const std::string& scan_id, const std::string& name, const std::string& actor) {
  impl_->revision.fetch_add(1);
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(Transaction tx, Transaction::begin(impl_->db));
  ASSIGN_OR_RETURN(Statement st, impl_->db.prepare("DELETE FROM tape_measurements WHERE scan_id = ? AND name = ?"));
  RETURN_IF_ERROR(st.bind(1, scan_id).bind(2, name).run());
  if (sqlite3_changes(impl_->db.handle()) == 0)
    return not_found("archive: scan '" + scan_id + "' has no tape measurement '" + name + "'");
  RETURN_IF_ERROR(impl_->log(actor, "delete tape measurement", "scan", scan_id, name));
  return tx.commit();
}

// --- audit, export, verify ---------------------------------------------------

StatusOr<std::vector<AuditEntry>> Archive::audit(const std::string& target_id, int limit) const {
  std::lock_guard lock(impl_->mu);
  ASSIGN_OR_RETURN(Statement st,
                   impl_->db.prepare("SELECT id, at, actor, action, target_kind, target_id, detail FROM audit "
                                     "WHERE ?1 = '' OR target_id = ?1 ORDER BY id DESC LIMIT ?2"));
  st.bind(1, target_id).bind(2, limit);
  std::vector<AuditEntry> out;
  for (;;) {
    ASSIGN_OR_RETURN(bool row, st.step());
    if (!row) break;
    out.push_back({st.integer(0), st.text(1), st.text(2), st.text(3), st.text(4), st.text(5), st.text(6)});
  }
  return out;
}

Status Archive::log(const std::string& actor, const std::string& action, const std::string& target_kind,
                    const std::string& target_id, const std::string& detail) {
  std::lock_guard lock(impl_->mu);
  return impl_->log(actor, action, target_kind, target_id, detail);
}

Status Archive::export_customer(const std::string& id, const std::string& dest, const std::string& actor) {
  ASSIGN_OR_RETURN(Customer c, customer(id));
  ScanQuery q;
  q.customer_id = id;
  q.limit = 1 << 30;
  ASSIGN_OR_RETURN(std::vector<ScanRecord> records, scans(q));
  nlohmann::json doc = {{"schema", "bodyscan.customer-export/1"},
                        {"exported_at", now_iso()},
                        {"customer",
                         {{"id", c.id},
                          {"name", c.name ? nlohmann::json(*c.name) : nlohmann::json()},
                          {"contact", c.contact ? nlohmann::json(*c.contact) : nlohmann::json()},
                          {"created_at", c.created_at},
                          {"consent", c.consent ? nlohmann::json{{"given_at", c.consent->given_at},
                                                                 {"recorded_by", c.consent->recorded_by},
                                                                 {"terms", c.consent->terms}}
                                                : nlohmann::json()}}},
                        {"scans", nlohmann::json::array()},
                        {"audit", nlohmann::json::array()}};
  const fs::path out(dest);
  RETURN_IF_ERROR(make_dirs(out / "scans"));
  auto add_audit = [&](const std::string& target) -> Status {
    ASSIGN_OR_RETURN(std::vector<AuditEntry> entries, audit(target, 1 << 30));
    for (const AuditEntry& e : entries)
      doc["audit"].push_back({{"at", e.at},
                              {"actor", e.actor},
                              {"action", e.action},
                              {"target_kind", e.target_kind},
                              {"target_id", e.target_id},
                              {"detail", e.detail}});
    return Status::Ok();
  };
  RETURN_IF_ERROR(add_audit(id));
  for (const ScanRecord& r : records) {
    nlohmann::json s = Impl::manifest(r);
    s["status_reason"] = r.status_reason;
    s["measurements"] = nlohmann::json::array();
    if (r.status == ScanStatus::kComplete) {
      for (const ScanVersion& v : r.versions) {
        ASSIGN_OR_RETURN(std::vector<MeasurementRecord> ms, measurements(r.id, v.version));
        for (const MeasurementRecord& m : ms)
          if (m.version == v.version) s["measurements"].push_back(to_json(m));
      }
      std::error_code ec;
      fs::copy(impl_->scan_dir(r.id), out / "scans" / r.id,
               fs::copy_options::recursive | fs::copy_options::overwrite_existing, ec);
      if (ec) return io_error("archive: cannot copy scan " + r.id + " to " + dest + ": " + ec.message());
    }
    ASSIGN_OR_RETURN(std::vector<TapeMeasurement> tape, tape_measurements(r.id));
    s["tape_measurements"] = nlohmann::json::array();
    for (const TapeMeasurement& t : tape) s["tape_measurements"].push_back(to_json(t));
    doc["scans"].push_back(std::move(s));
    RETURN_IF_ERROR(add_audit(r.id));
  }
  RETURN_IF_ERROR(write_file_atomically((out / "customer.json").string(), doc.dump(1)));
  return log(actor, "export customer", "customer", id, dest);
}

Status Archive::verify() const {
  std::lock_guard lock(impl_->mu);
  {
    ASSIGN_OR_RETURN(Statement st, impl_->db.prepare("PRAGMA integrity_check"));
    ASSIGN_OR_RETURN(bool row, st.step());
    if (!row || st.text(0) != "ok")
      return io_error("archive: the database fails its integrity check: " + (row ? st.text(0) : ""));
    ASSIGN_OR_RETURN(Statement fk, impl_->db.prepare("PRAGMA foreign_key_check"));
    ASSIGN_OR_RETURN(bool bad, fk.step());
    if (bad) return io_error("archive: a record points at a missing " + fk.text(2));
  }
  ASSIGN_OR_RETURN(std::vector<std::string> complete, impl_->ids("SELECT id FROM scans WHERE status = 'complete'"));
  for (const std::string& id : complete) {
    ASSIGN_OR_RETURN(ScanRecord r, impl_->record(id));
    auto manifest = slurp(impl_->scan_dir(id) / "manifest.json");
    if (!manifest.ok() || *manifest != Impl::manifest(r).dump(1))
      return io_error("archive: scan " + id + "'s manifest does not match the index");
    auto check = [&](int version, const std::vector<ArchivedFile>& files) -> Status {
      for (const ArchivedFile& f : files) {
        auto bytes = slurp(impl_->version_dir(id, version) / f.name);
        if (!bytes.ok()) return io_error("archive: scan " + id + " is missing " + f.name);
        if (bytes->size() != f.bytes || blake2b_hex(*bytes) != f.blake2b)
          return io_error("archive: scan " + id + "'s " + f.name + " does not match its checksum");
      }
      return Status::Ok();
    };
    RETURN_IF_ERROR(check(kRawVersion, r.raw));
    for (const ScanVersion& v : r.versions) RETURN_IF_ERROR(check(v.version, v.files));
  }
  return Status::Ok();
}

}  // namespace bodyscan::storage
