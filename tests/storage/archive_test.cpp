#include "storage/archive/archive.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <thread>

#include "bench/json_figures.hpp"
#include "tests/test_data.hpp"

namespace bodyscan::storage {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string bytes(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::string s(n, '\0');
  for (char& c : s) c = static_cast<char>(rng());
  return s;
}

ScanResults results(uint32_t seed, const std::string& algorithm = "surface/1") {
  ScanResults r;
  r.files["mesh.glb"] = bytes(50000, seed);
  r.files["points.drc"] = bytes(30000, seed + 1);
  r.files["measurements.json"] = R"({"schema": "bodyscan.measurements/1"})";
  r.algorithms = {{"surface", algorithm}};
  MeasurementRecord waist;
  waist.name = "waist_girth", waist.label = "Waist girth", waist.kind = "girth", waist.iso_clause = "5.3.10";
  waist.value_mm = 812.5 + seed;
  waist.geometry = {{"path", {{0, 1000, 100}, {100, 1000, 0}}}};
  r.measurements.push_back(waist);
  return r;
}

const nlohmann::json kRig = {{"name", "thesis"}};

// Every file under dir, as bytes.
std::string everything(const fs::path& dir) {
  std::string all;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) all += slurp(e.path());
  return all;
}

// People's names and bodies: whatever the umask, the archive's folder is its
// owner's alone and its database is created private (SQLite gives the -wal and
// -shm files the database's mode).
TEST(Archive, ItsFolderAndDatabaseArePrivate) {
  const mode_t old_mask = umask(0022);
  const std::string dir = testing::temp_dir() + "/archive";
  fs::create_directories(dir);
  fs::permissions(dir, fs::perms::all);  // left open by someone
  {
    auto a = Archive::open(dir);
    ASSERT_TRUE(a.ok()) << a.status().message();
    ASSERT_TRUE((*a)->add_customer(std::string("Private Person"), std::nullopt, "test").ok());
    EXPECT_EQ(fs::status(dir).permissions(), fs::perms::owner_all);
    for (const char* name : {"archive.db", "archive.db-wal", "archive.lock"})
      EXPECT_EQ(fs::status(dir + "/" + name).permissions() & (fs::perms::group_all | fs::perms::others_all),
                fs::perms::none)
          << name;
  }
  umask(old_mask);
}

TEST(Archive, AScanIsStoredWithItsRecordsFilesAndChecksums) {
  const std::string dir = testing::temp_dir();
  auto a = Archive::open(dir);
  ASSERT_TRUE(a.ok()) << a.status().message();
  Archive& ar = **a;
  auto c = ar.add_customer("Ana Souza", "ana@example.com", "op1");
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_EQ(c->id.rfind("c_", 0), 0u);
  auto cal = ar.add_calibration(kRig, {{"cameras", 3}}, "op1");
  ASSERT_TRUE(cal.ok()) << cal.status().message();
  auto id = ar.begin_scan(c->id, "op1", kRig, *cal);
  ASSERT_TRUE(id.ok()) << id.status().message();
  ASSERT_TRUE(ar.put_raw(*id, "stripes.bin", bytes(100000, 7)).ok());
  ASSERT_TRUE(ar.complete_scan(*id, results(1)).ok());

  auto r = ar.scan(*id);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->status, ScanStatus::kComplete);
  EXPECT_EQ(r->customer_id, c->id);
  EXPECT_EQ(r->calibration_id, *cal);
  EXPECT_EQ(r->rig, kRig);
  EXPECT_EQ(r->current_version, 1);
  ASSERT_EQ(r->versions.size(), 1u);
  EXPECT_EQ(r->versions[0].files.size(), 3u);
  ASSERT_EQ(r->raw.size(), 1u);
  EXPECT_EQ(r->raw[0].bytes, 100000u);
  auto path = ar.file_path(*id, 0, "mesh.glb");
  ASSERT_TRUE(path.ok());
  EXPECT_EQ(slurp(*path), bytes(50000, 1));
  EXPECT_EQ(slurp(*ar.file_path(*id, -1, "stripes.bin")), bytes(100000, 7));
  EXPECT_EQ(ar.file_path(*id, 0, "nope.glb").status().code(), StatusCode::kNotFound);
  EXPECT_EQ(ar.file_path(*id, 0, "../archive.db").status().code(), StatusCode::kNotFound);
  auto ms = ar.measurements(*id);
  ASSERT_TRUE(ms.ok());
  ASSERT_EQ(ms->size(), 1u);
  EXPECT_EQ((*ms)[0].iso_clause, "5.3.10");
  EXPECT_DOUBLE_EQ((*ms)[0].value_mm, 813.5);
  EXPECT_EQ((*ms)[0].geometry["path"][1][0], 100);
  auto cal_back = ar.calibration(*cal);
  ASSERT_TRUE(cal_back.ok());
  EXPECT_EQ((*cal_back)["calibration"]["cameras"], 3);
  // The manifest in the scan's folder says the same as the index.
  const nlohmann::json manifest = nlohmann::json::parse(slurp(fs::path(dir) / "scans" / *id / "manifest.json"));
  EXPECT_EQ(manifest["status"], "complete");
  EXPECT_EQ(manifest["versions"][0]["files"].size(), 3u);
  EXPECT_TRUE(ar.verify().ok()) << ar.verify().message();
  // Tampering shows.
  { std::ofstream(*path, std::ios::binary | std::ios::app) << "x"; }
  const Status bad = ar.verify();
  EXPECT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("mesh.glb"), std::string::npos) << bad.message();
  // The audit log says who did what.
  auto log = ar.audit(*id);
  ASSERT_TRUE(log.ok());
  ASSERT_GE(log->size(), 2u);
  EXPECT_EQ(log->back().action, "start scan");
  EXPECT_EQ(log->back().actor, "op1");
}

TEST(Archive, ReprocessingKeepsTheOldResultsAsAVersion) {
  auto a = Archive::open(testing::temp_dir());
  ASSERT_TRUE(a.ok());
  Archive& ar = **a;
  const Customer c = *ar.add_customer(std::nullopt, std::nullopt, "op");
  const std::string id = *ar.begin_scan(c.id, "op", kRig, "");
  ASSERT_TRUE(ar.complete_scan(id, results(1, "surface/1")).ok());
  MeasurementRecord mine;
  mine.scan_id = id, mine.name = "sleeve", mine.label = "Sleeve", mine.kind = "surface_length", mine.value_mm = 600;
  auto saved = ar.save_measurement(mine, "tailor");
  ASSERT_TRUE(saved.ok()) << saved.status().message();
  auto v2 = ar.add_version(id, results(2, "surface/2"), "admin");
  ASSERT_TRUE(v2.ok()) << v2.status().message();
  EXPECT_EQ(*v2, 2);
  const ScanRecord r = *ar.scan(id);
  EXPECT_EQ(r.current_version, 2);
  ASSERT_EQ(r.versions.size(), 2u);
  EXPECT_EQ(r.versions[0].algorithms["surface"], "surface/1");
  EXPECT_EQ(r.versions[1].algorithms["surface"], "surface/2");
  EXPECT_EQ(slurp(*ar.file_path(id, 1, "mesh.glb")), bytes(50000, 1));
  EXPECT_EQ(slurp(*ar.file_path(id, 0, "mesh.glb")), bytes(50000, 2));
  // The automatic set per version; what staff saved stays with the scan.
  auto now = *ar.measurements(id);
  ASSERT_EQ(now.size(), 2u);
  EXPECT_DOUBLE_EQ(now[0].value_mm, 814.5);
  EXPECT_EQ(now[1].source, "user");
  EXPECT_EQ(now[1].created_by, "tailor");
  EXPECT_DOUBLE_EQ((*ar.measurements(id, 1))[0].value_mm, 813.5);
  EXPECT_TRUE(ar.delete_measurement(id, *saved, "tailor").ok());
  EXPECT_EQ(ar.delete_measurement(id, *saved, "tailor").code(), StatusCode::kNotFound);
  EXPECT_TRUE(ar.verify().ok()) << ar.verify().message();
}

TEST(Archive, AFailedScanSaysWhyAndKeepsNoFiles) {
  const std::string dir = testing::temp_dir();
  auto a = Archive::open(dir);
  ASSERT_TRUE(a.ok());
  Archive& ar = **a;
  const Customer c = *ar.add_customer("B", std::nullopt, "op");
  const std::string id = *ar.begin_scan(c.id, "op", kRig, "");
  ASSERT_TRUE(ar.put_raw(id, "stripes.bin", "abc").ok());
  ASSERT_TRUE(ar.end_scan(id, ScanStatus::kFailed, "camera front-left stopped answering at frame 812").ok());
  const ScanRecord r = *ar.scan(id);
  EXPECT_EQ(r.status, ScanStatus::kFailed);
  EXPECT_EQ(r.status_reason, "camera front-left stopped answering at frame 812");
  EXPECT_TRUE(r.raw.empty());
  EXPECT_FALSE(fs::exists(fs::path(dir) / "scans" / id));
  EXPECT_EQ(ar.complete_scan(id, results(1)).code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ(ar.begin_scan("c_nobody", "op", kRig, "").status().code(), StatusCode::kNotFound);
  EXPECT_EQ(ar.set_scan_calibration(id, "k_none").code(), StatusCode::kFailedPrecondition);  // not running
  EXPECT_EQ(ar.put_raw(id, "x", "y").code(), StatusCode::kFailedPrecondition);
  const std::string other = *ar.begin_scan(c.id, "op", kRig, "");
  EXPECT_EQ(ar.set_scan_calibration(other, "k_none").code(), StatusCode::kNotFound);
  ScanResults evil = results(3);
  evil.files["../../escape"] = "x";
  EXPECT_EQ(ar.complete_scan(other, evil).code(), StatusCode::kInvalidArgument);
  EXPECT_FALSE(fs::exists(fs::path(dir) / "escape"));
}

TEST(Archive, OpeningRepairsWhatACrashLeft) {
  const std::string dir = testing::temp_dir();
  std::string running, done, customer;
  {
    auto a = Archive::open(dir);
    ASSERT_TRUE(a.ok());
    customer = (*a)->add_customer("C", std::nullopt, "op")->id;
    done = *(*a)->begin_scan(customer, "op", kRig, "");
    ASSERT_TRUE((*a)->complete_scan(done, results(1)).ok());
    running = *(*a)->begin_scan(customer, "op", kRig, "");
    ASSERT_TRUE((*a)->put_raw(running, "stripes.bin", "partial").ok());
  }
  // What a crash can leave besides: half a file, a result folder the index never
  // took, a folder of a scan it never knew, a stale manifest.
  const fs::path scans = fs::path(dir) / "scans";
  { std::ofstream(scans / done / "v1" / "mesh.glb.tmp-999") << "half"; }
  fs::create_directories(scans / done / "v2");
  { std::ofstream(scans / done / "v2" / "mesh.glb") << "never committed"; }
  fs::create_directories(scans / "s_20000101_000000_deadbeef");
  { std::ofstream(scans / done / "manifest.json") << "{}"; }

  auto a = Archive::open(dir);
  ASSERT_TRUE(a.ok()) << a.status().message();
  const RecoveryReport& rep = (*a)->recovery();
  ASSERT_EQ(rep.scans_failed.size(), 1u);
  EXPECT_EQ(rep.scans_failed[0], running);
  EXPECT_EQ(rep.versions_removed, 1u);
  EXPECT_EQ(rep.orphans_removed, 1u);
  EXPECT_EQ(rep.temp_files_removed, 1u);
  const ScanRecord r = *(*a)->scan(running);
  EXPECT_EQ(r.status, ScanStatus::kFailed);
  EXPECT_NE(r.status_reason.find("interrupted"), std::string::npos);
  EXPECT_FALSE(fs::exists(scans / running));
  EXPECT_FALSE(fs::exists(scans / done / "v2"));
  EXPECT_EQ((*a)->scan(done)->status, ScanStatus::kComplete);
  EXPECT_TRUE((*a)->verify().ok()) << (*a)->verify().message();
}

TEST(Archive, OneProcessAtATimeAndADamagedDatabaseSaysSo) {
  const std::string dir = testing::temp_dir();
  {
    auto a = Archive::open(dir);
    ASSERT_TRUE(a.ok());
    auto b = Archive::open(dir);
    ASSERT_FALSE(b.ok());
    EXPECT_EQ(b.status().code(), StatusCode::kUnavailable);
    EXPECT_NE(b.status().message().find("in use"), std::string::npos);
  }
  const std::string junk = testing::temp_dir();
  { std::ofstream(fs::path(junk) / "archive.db") << std::string(8192, 'J'); }
  auto c = Archive::open(junk);
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.status().message().find("damaged"), std::string::npos) << c.status().message();
}

TEST(Archive, FindsScansByCustomerTextAndDate) {
  auto a = Archive::open(testing::temp_dir());
  ASSERT_TRUE(a.ok());
  Archive& ar = **a;
  const Customer ana = *ar.add_customer("Ana Souza", "ana.souza@example.org", "op");
  const Customer bo = *ar.add_customer("Bo Li", std::nullopt, "op");
  for (const Customer* c : {&ana, &ana, &bo})
    ASSERT_TRUE(ar.complete_scan(*ar.begin_scan(c->id, "maria", kRig, ""), results(1)).ok());
  ScanQuery q;
  q.customer_id = ana.id;
  EXPECT_EQ(ar.scans(q)->size(), 2u);
  q = {};
  q.text = "souza";
  EXPECT_EQ(ar.scans(q)->size(), 2u);
  q.text = "MARIA";
  EXPECT_EQ(ar.scans(q)->size(), 3u);
  // By contact, and by words in any order, each in any field.
  q.text = "example.org";
  EXPECT_EQ(ar.scans(q)->size(), 2u);
  q.text = "souza ana";
  EXPECT_EQ(ar.scans(q)->size(), 2u);
  q.text = "  Souza   maria ";
  EXPECT_EQ(ar.scans(q)->size(), 2u);
  q.text = "souza bo";
  EXPECT_EQ(ar.scans(q)->size(), 0u);
  q.text = "a b c d e f g h i";
  EXPECT_EQ(ar.scans(q).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(ar.customers("souza ana")->size(), 1u);
  EXPECT_EQ(ar.customers("ana.souza@")->size(), 1u);
  EXPECT_EQ(ar.customers("")->size(), 2u);
  q = {};
  q.from = "2000-01-01";
  q.to = "2000-12-31";
  EXPECT_EQ(ar.scans(q)->size(), 0u);
  q.to = "2999";
  EXPECT_EQ(ar.scans(q)->size(), 3u);
  EXPECT_EQ(ar.customers("li")->size(), 1u);
}

TEST(Archive, DeletingACustomerLeavesNothingOfThem) {
  const std::string dir = testing::temp_dir();
  auto a = Archive::open(dir);
  ASSERT_TRUE(a.ok());
  Archive& ar = **a;
  const Customer keep = *ar.add_customer("Kept Person", "kept@example.com", "op");
  const std::string kept_scan = *ar.begin_scan(keep.id, "op", kRig, "");
  ASSERT_TRUE(ar.complete_scan(kept_scan, results(5)).ok());
  ASSERT_TRUE(ar.record_consent(keep.id, "the shop's terms", "op").ok());
  const Customer gone = *ar.add_customer("Zora Quintrell", "zora.q@example.org", "op");
  ASSERT_TRUE(ar.record_consent(gone.id, "ZORA-TERMS: as agreed with Zora", "op").ok());
  std::vector<std::string> scans;
  for (int i = 0; i < 3; ++i) {
    scans.push_back(*ar.begin_scan(gone.id, "op", kRig, ""));
    ASSERT_TRUE(ar.put_raw(scans.back(), "stripes.bin", "ZORA-RAW-" + bytes(1000, 40 + i)).ok());
    ScanResults r = results(10 + i);
    r.files["measurements.json"] = R"({"note": "Zora Quintrell's scan"})";
    ASSERT_TRUE(ar.complete_scan(scans.back(), r).ok());
  }
  MeasurementRecord m;
  m.scan_id = scans[0], m.name = "zora_special", m.label = "Zora's line", m.kind = "girth", m.value_mm = 1;
  ASSERT_TRUE(ar.save_measurement(m, "tailor").ok());
  ASSERT_TRUE(ar.put_tape_measurement({scans[0], "", "waist_girth", 777.5, "ZORA-TAPER", "", ""}, "tailor").ok());

  // Exporting first: everything held about her.
  const std::string out = testing::temp_dir();
  ASSERT_TRUE(ar.export_customer(gone.id, out, "admin").ok());
  const nlohmann::json doc = nlohmann::json::parse(slurp(fs::path(out) / "customer.json"));
  EXPECT_EQ(doc["customer"]["name"], "Zora Quintrell");
  EXPECT_EQ(doc["customer"]["contact"], "zora.q@example.org");
  EXPECT_EQ(doc["customer"]["consent"]["terms"], "ZORA-TERMS: as agreed with Zora");
  EXPECT_EQ(doc["customer"]["consent"]["recorded_by"], "op");
  ASSERT_EQ(doc["scans"].size(), 3u);
  size_t user_lines = 0, audit_for_scans = 0;
  for (const auto& s : doc["scans"])
    for (const auto& mm : s["measurements"]) user_lines += mm["source"] == "user";
  for (const auto& e : doc["audit"]) audit_for_scans += e["target_kind"] == "scan";
  EXPECT_EQ(user_lines, 1u);
  EXPECT_EQ(doc["scans"][0]["tape_measurements"].size() + doc["scans"][1]["tape_measurements"].size() +
                doc["scans"][2]["tape_measurements"].size(),
            1u);
  EXPECT_GE(audit_for_scans, 6u);  // started and completed, each
  for (const std::string& s : scans) {
    EXPECT_EQ(slurp(fs::path(out) / "scans" / s / "v1" / "mesh.glb"), slurp(*ar.file_path(s, 0, "mesh.glb")));
    EXPECT_TRUE(fs::exists(fs::path(out) / "scans" / s / "raw" / "stripes.bin"));
  }

  ASSERT_TRUE(ar.delete_customer(gone.id, "admin").ok());
  EXPECT_EQ(ar.customer(gone.id).status().code(), StatusCode::kNotFound);
  for (const std::string& s : scans) {
    EXPECT_EQ(ar.scan(s).status().code(), StatusCode::kNotFound);
    EXPECT_FALSE(fs::exists(fs::path(dir) / "scans" / s));
  }
  // Not one byte of theirs anywhere in the archive's folder: the database, its
  // write-ahead log, the files.
  const std::string all = everything(dir);
  for (const std::string& needle :
       {std::string("Zora Quintrell"), std::string("zora.q@example.org"), gone.id, scans[0], scans[1], scans[2],
        std::string("ZORA-RAW-"), std::string("zora_special"), std::string("ZORA-TERMS"), std::string("ZORA-TAPER")})
    EXPECT_EQ(all.find(needle), std::string::npos) << needle;
  // The others are untouched, and the log says an erasure happened, by whom.
  EXPECT_EQ(ar.scan(kept_scan)->status, ScanStatus::kComplete);
  ASSERT_TRUE(ar.customer(keep.id)->consent.has_value());
  EXPECT_NE(all.find("Kept Person"), std::string::npos);
  auto log = ar.audit();
  ASSERT_TRUE(log.ok());
  EXPECT_EQ(log->front().action, "erase customer");
  EXPECT_EQ(log->front().actor, "admin");
  EXPECT_TRUE(ar.verify().ok()) << ar.verify().message();
  EXPECT_EQ(ar.delete_customer(gone.id, "admin").code(), StatusCode::kNotFound);
}

// Tape values: one per scan and measurement (entering again replaces it), only
// for the scan's automatic measurements, within 1 mm to 3 m, with who measured.
TEST(Archive, KeepsOneTapeValuePerScanAndMeasurement) {
  auto a = Archive::open(testing::temp_dir());
  ASSERT_TRUE(a.ok());
  Archive& ar = **a;
  const Customer c = *ar.add_customer("Tape Person", std::nullopt, "op");
  const std::string scan = *ar.begin_scan(c.id, "op", kRig, "");
  EXPECT_EQ(ar.put_tape_measurement({scan, "", "waist_girth", 800, "Ada", "", ""}, "op").code(),
            StatusCode::kFailedPrecondition)
      << "a running scan has no values to compare with";
  ASSERT_TRUE(ar.complete_scan(scan, results(1)).ok());
  ASSERT_TRUE(ar.put_tape_measurement({scan, "", "waist_girth", 800, "Ada", "", ""}, "op").ok());
  ASSERT_TRUE(ar.put_tape_measurement({scan, "", "waist_girth", 805, "Ben", "", ""}, "tailor").ok());
  EXPECT_EQ(ar.put_tape_measurement({scan, "", "hip_girth", 900, "Ada", "", ""}, "op").code(), StatusCode::kNotFound);
  EXPECT_EQ(ar.put_tape_measurement({scan, "", "waist_girth", 0.5, "Ada", "", ""}, "op").code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(ar.put_tape_measurement({scan, "", "waist_girth", 3001, "Ada", "", ""}, "op").code(),
            StatusCode::kInvalidArgument);
  EXPECT_EQ(ar.put_tape_measurement({scan, "", "waist_girth", 800, "", "", ""}, "op").code(),
            StatusCode::kInvalidArgument);
  auto tape = ar.tape_measurements(scan);
  ASSERT_TRUE(tape.ok());
  ASSERT_EQ(tape->size(), 1u);
  EXPECT_EQ((*tape)[0].customer_id, c.id);
  EXPECT_EQ((*tape)[0].value_mm, 805);
  EXPECT_EQ((*tape)[0].measured_by, "Ben");
  EXPECT_EQ((*tape)[0].entered_by, "tailor");
  EXPECT_EQ(ar.audit(scan, 1)->front().action, "enter tape measurement");
  ASSERT_TRUE(ar.delete_tape_measurement(scan, "waist_girth", "op").ok());
  EXPECT_EQ(ar.delete_tape_measurement(scan, "waist_girth", "op").code(), StatusCode::kNotFound);
  EXPECT_TRUE(ar.tape_measurements()->empty());
}

// A customer's consent: the terms word for word, when, and who recorded it; the
// latest is the customer's, in the list as in the record.
TEST(Archive, KeepsEachCustomersConsent) {
  const std::string dir = testing::temp_dir();
  auto a = Archive::open(dir);
  ASSERT_TRUE(a.ok());
  Archive& ar = **a;
  const Customer c = *ar.add_customer("Ada Lovelace", std::nullopt, "op");
  EXPECT_FALSE(c.consent.has_value());
  EXPECT_FALSE(ar.customer(c.id)->consent.has_value());
  EXPECT_EQ(ar.record_consent("c_0000000000000000", "terms", "op").status().code(), StatusCode::kNotFound);
  EXPECT_EQ(ar.record_consent(c.id, "", "op").status().code(), StatusCode::kInvalidArgument);
  auto first = ar.record_consent(c.id, "terms one", "olivia");
  ASSERT_TRUE(first.ok()) << first.status().message();
  EXPECT_EQ(first->recorded_by, "olivia");
  EXPECT_TRUE(first->given_at.rfind("20", 0) == 0 && first->given_at.back() == 'Z') << first->given_at;  // ISO, UTC
  ASSERT_TRUE(ar.record_consent(c.id, "terms two", "oscar").ok());
  const std::optional<Consent> k = ar.customer(c.id)->consent;
  ASSERT_TRUE(k.has_value());
  EXPECT_EQ(k->terms, "terms two");
  EXPECT_EQ(k->recorded_by, "oscar");
  auto listed = ar.customers("Lovelace");
  ASSERT_TRUE(listed.ok());
  ASSERT_EQ(listed->size(), 1u);
  ASSERT_TRUE((*listed)[0].consent.has_value());
  EXPECT_EQ((*listed)[0].consent->terms, "terms two");
  EXPECT_EQ(ar.audit(c.id)->front().action, "record consent");
}

TEST(Archive, AFullDiskGivesAClearErrorAndLosesNothing) {
  const std::string dir = testing::temp_dir();
  std::string kept;
  {
    auto a = Archive::open(dir);
    ASSERT_TRUE(a.ok());
    const Customer c = *(*a)->add_customer("D", std::nullopt, "op");
    kept = *(*a)->begin_scan(c.id, "op", kRig, "");
    ASSERT_TRUE((*a)->complete_scan(kept, results(1)).ok());
  }
  // A child whose files may not grow past 64 kB: the kernel refuses the write as a
  // full disk would. It reports what the archive said on a pipe.
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  const pid_t pid = fork();
  if (pid == 0) {
    signal(SIGXFSZ, SIG_IGN);
    rlimit lim{65536, 65536};
    setrlimit(RLIMIT_FSIZE, &lim);
    auto a = Archive::open(dir);
    std::string msg = a.ok() ? "" : "open: " + a.status().message();
    if (a.ok()) {
      auto c = (*a)->customers();
      const std::string id = *(*a)->begin_scan(c->front().id, "op", kRig, "");
      ScanResults big = results(2);
      big.files["mesh.ply"] = bytes(1 << 20, 3);
      const Status s = (*a)->complete_scan(id, big);
      msg = s.ok() ? "stored?!" : s.message();
      if (!s.ok()) (*a)->end_scan(id, ScanStatus::kFailed, "could not store the results: " + s.message());
    }
    (void)!write(fds[1], msg.data(), msg.size());
    _exit(0);
  }
  close(fds[1]);
  std::string said;
  char buf[512];
  for (ssize_t n; (n = read(fds[0], buf, sizeof buf)) > 0;) said.append(buf, static_cast<size_t>(n));
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  EXPECT_NE(said.find("File too large"), std::string::npos) << said;
  EXPECT_NE(said.find("mesh.ply"), std::string::npos) << said;
  auto a = Archive::open(dir);
  ASSERT_TRUE(a.ok());
  EXPECT_TRUE((*a)->verify().ok()) << (*a)->verify().message();
  const auto all = *(*a)->scans();
  ASSERT_EQ(all.size(), 2u);
  for (const ScanRecord& r : all) {
    if (r.id == kept)
      EXPECT_EQ(r.status, ScanStatus::kComplete);
    else
      EXPECT_EQ(r.status, ScanStatus::kFailed) << r.status_reason;
  }
  EXPECT_EQ(slurp(*(*a)->file_path(kept, 0, "mesh.glb")), bytes(50000, 1));
}

// The crash drill: a child stores scans as fast as it can (customers, raw data,
// results, reprocessing, deletions) and is killed with SIGKILL at a random moment;
// the archive is reopened and every scan the child saw complete must be there,
// whole. BODYSCAN_CRASH_POINTS sets how many kills; BODYSCAN_CRASH_JSON=F.json
// writes the drill's counts there for docs/benchmarks.md (bench/tables.py).
TEST(ArchiveCrash, SigkillAtRandomPointsLosesNoCompletedScan) {
  const char* env = std::getenv("BODYSCAN_CRASH_POINTS");
  const int points = env ? std::atoi(env) : 12;
  const std::string dir = testing::temp_dir();
  std::set<std::string> completed, deleted;
  std::mt19937 rng(2026);
  size_t recovered_running = 0, kills_mid_write = 0;
  for (int k = 0; k < points; ++k) {
    int fds[2];
    ASSERT_EQ(pipe(fds), 0);
    const pid_t pid = fork();
    if (pid == 0) {
      close(fds[0]);
      auto a = Archive::open(dir);
      if (!a.ok()) _exit(3);
      Archive& ar = **a;
      std::mt19937 local(static_cast<uint32_t>(k) * 7919u);
      std::vector<std::string> mine;
      for (int i = 0;; ++i) {
        auto cs = ar.customers();
        std::string customer = cs->empty() || i % 4 == 0
                                   ? ar.add_customer("P" + std::to_string(i), std::nullopt, "op")->id
                                   : (*cs)[local() % cs->size()].id;
        auto id = ar.begin_scan(customer, "op", kRig, "");
        if (!id.ok()) _exit(4);
        if (!ar.put_raw(*id, "stripes.bin", bytes(20000 + local() % 20000, local())).ok()) _exit(5);
        if (!ar.complete_scan(*id, results(local() % 1000)).ok()) _exit(6);
        const std::string line = "C " + *id + "\n";
        (void)!write(fds[1], line.data(), line.size());
        mine.push_back(*id);
        if (i % 3 == 2 && !ar.add_version(mine[local() % mine.size()], results(local() % 1000, "surface/2"), "op").ok())
          _exit(7);
        if (i % 5 == 4) {
          const std::string victim = mine[local() % mine.size()];
          const std::string intent = "d " + victim + "\n";
          (void)!write(fds[1], intent.data(), intent.size());
          if (!ar.delete_scan(victim, "op").ok()) _exit(8);
          mine.erase(std::find(mine.begin(), mine.end(), victim));
        }
      }
    }
    close(fds[1]);
    std::this_thread::sleep_for(std::chrono::microseconds(2000 + rng() % 250000));
    kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the child stopped by itself, code " << WEXITSTATUS(status);
    std::string said;
    char buf[4096];
    for (ssize_t n; (n = read(fds[0], buf, sizeof buf)) > 0;) said.append(buf, static_cast<size_t>(n));
    close(fds[0]);
    std::istringstream lines(said);
    std::string tag, id;
    while (lines >> tag >> id) {
      if (tag == "C")
        completed.insert(id);
      else
        deleted.insert(id);  // may or may not have happened before the kill
    }
    auto a = Archive::open(dir);
    ASSERT_TRUE(a.ok()) << "kill " << k << ": " << a.status().message();
    recovered_running += (*a)->recovery().scans_failed.size();
    kills_mid_write += (*a)->recovery().temp_files_removed > 0;
    const Status v = (*a)->verify();
    ASSERT_TRUE(v.ok()) << "kill " << k << ": " << v.message();
    for (const std::string& s : completed) {
      auto r = (*a)->scan(s);
      if (deleted.count(s) && !r.ok()) continue;
      ASSERT_TRUE(r.ok()) << "kill " << k << ": completed scan " << s << " is lost";
      EXPECT_EQ(r->status, ScanStatus::kComplete) << s;
    }
    ScanQuery all;
    all.limit = 1 << 30;
    const std::vector<ScanRecord> records = *(*a)->scans(all);
    for (const ScanRecord& r : records) {
      EXPECT_NE(r.status, ScanStatus::kRunning) << r.id;
      if (r.status == ScanStatus::kComplete) {
        // Complete means whole: the raw data and every result file of every version.
        EXPECT_TRUE(fs::exists(fs::path(dir) / "scans" / r.id / "manifest.json"));
        EXPECT_EQ(r.raw.size(), 1u) << r.id;
        ASSERT_FALSE(r.versions.empty()) << r.id;
        for (const ScanVersion& version : r.versions) {
          ASSERT_EQ(version.files.size(), 3u) << r.id << " v" << version.version;
          auto glb = (*a)->file_path(r.id, version.version, "mesh.glb");
          ASSERT_TRUE(glb.ok()) << glb.status().message();
          EXPECT_EQ(fs::file_size(*glb), 50000u);
        }
      } else {
        EXPECT_FALSE(fs::exists(fs::path(dir) / "scans" / r.id));
      }
    }
  }
  std::printf(
      "crash drill: %d kills, %zu scans completed before them, %zu interrupted scans marked failed, "
      "%zu kills left half-written files; 0 completed scans lost\n",
      points, completed.size(), recovered_running, kills_mid_write);
  if (const char* json = std::getenv("BODYSCAN_CRASH_JSON")) {
    const nlohmann::json record = {{"kills", points},
                                   {"completed", completed.size()},
                                   {"interrupted_marked_failed", recovered_running},
                                   {"kills_mid_write", kills_mid_write},
                                   {"completed_lost", 0}};
    const std::string command = "BODYSCAN_CRASH_POINTS=" + std::to_string(points) +
                                " storage_tests --gtest_filter=ArchiveCrash.SigkillAtRandomPointsLosesNoCompletedScan";
    EXPECT_TRUE(bench::write_figures(json, bench::run_record(command), nlohmann::json::array({record})));
  }
}

}  // namespace
}  // namespace bodyscan::storage
