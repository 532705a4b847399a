// `bodyscan scan --archive`, `bodyscan reprocess` and `bodyscan archive` as shop IT
// runs them.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <random>
#include <sstream>
#include <string>
#include <thread>

#include "recon/io/ply.hpp"
#include "recon/measure/body_measurements.hpp"
#include "storage/archive/archive.hpp"
#include "storage/formats/draco_files.hpp"
#include "tests/app/cli_runner.hpp"
#include "tests/test_data.hpp"

namespace bodyscan {
namespace {

std::string first_word(const std::string& s) { return s.substr(0, s.find_first_of(" \n")); }

TEST(ArchiveCli, AScanIsArchivedAndMadeAgainFromItsRawRecord) {
  const std::string dir = testing::temp_dir();
  const std::string A = quote(dir + "/A"), D = quote(dir + "/D"), E = quote(dir + "/E");
  const CliResult r = bodyscan("scan --rig sim --every 12 --no-surface --archive " + A +
                                   " --new-customer Ana --operator maria --out " + D + " -q",
                               dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir + "/D/raw/stripes.bin"));
  // The folder's raw record gives the same cloud, byte for byte.
  const CliResult again = bodyscan("reprocess " + D + " --out " + E + " --no-surface", dir);
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(slurp(dir + "/D/points.ply"), slurp(dir + "/E/points.ply"));
  // --keep-sway: the sway is not looked for (every 12th step is too coarse to find
  // it anyway, and says so; ScanJob.ASwayingSubjectsSwayIsFoundAndUndone has one).
  const std::string K = quote(dir + "/K");
  const CliResult kept = bodyscan("reprocess " + D + " --out " + K + " --no-surface --keep-sway", dir);
  ASSERT_EQ(kept.exit_code, 0) << kept.err;
  EXPECT_FALSE(nlohmann::json::parse(slurp(dir + "/K/scan.json")).contains("sway_not_estimated"));
  EXPECT_TRUE(nlohmann::json::parse(slurp(dir + "/E/scan.json")).contains("sway_not_estimated"));

  const CliResult list = bodyscan("archive " + A + " list", dir);
  ASSERT_EQ(list.exit_code, 0) << list.err;
  EXPECT_NE(list.out.find("complete"), std::string::npos) << list.out;
  EXPECT_NE(list.out.find("operator maria"), std::string::npos) << list.out;
  const std::string scan = first_word(list.out);
  const CliResult customers = bodyscan("archive " + A + " customers ana", dir);
  EXPECT_NE(customers.out.find("Ana"), std::string::npos) << customers.out;

  // Reprocessed in the archive: a second version beside the first.
  const CliResult re = bodyscan("archive " + A + " reprocess " + scan + " --actor tailor1", dir);
  ASSERT_EQ(re.exit_code, 0) << re.err;
  EXPECT_NE(re.out.find("version 2"), std::string::npos) << re.out;
  const nlohmann::json shown = nlohmann::json::parse(bodyscan("archive " + A + " show " + scan, dir).out);
  ASSERT_EQ(shown["versions"].size(), 2u);
  EXPECT_EQ(shown["calibration"].get<std::string>().rfind("k_", 0), 0u);  // the calibration it ran on
  EXPECT_EQ(shown["rig"]["name"], "thesis");
  EXPECT_EQ(shown["versions"][0]["algorithms"]["surface"], "none");
  EXPECT_EQ(shown["raw"].size(), 2u);
  const CliResult verify = bodyscan("archive " + A + " verify", dir);
  EXPECT_EQ(verify.exit_code, 0) << verify.err;
  EXPECT_NE(verify.out.find("consistent"), std::string::npos) << verify.out;
}

// SIGKILL during real scans (the simulated rig, every 12th step): the next start
// finds each killed scan marked failed with the reason, and the scans before it whole.
TEST(ArchiveCli, AScanKilledMidwayIsMarkedFailedAndNothingElseIsLost) {
  const std::string dir = testing::temp_dir(), archive = dir + "/A";
  const CliResult first = bodyscan("scan --rig sim --every 12 --no-surface -q --archive " + quote(archive), dir);
  ASSERT_EQ(first.exit_code, 0) << first.err;
  std::mt19937 rng(7);
  for (int k = 0; k < 2; ++k) {
    const pid_t pid = fork();
    if (pid == 0) {
      const int null = open("/dev/null", O_WRONLY);
      dup2(null, 1), dup2(null, 2);
      execl(BODYSCAN_BIN, BODYSCAN_BIN, "scan", "--rig", "sim", "--every", "12", "--no-surface", "-q", "--archive",
            archive.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1500 + rng() % 3000));
    kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the scan ended before the kill; kill sooner";
  }
  const CliResult verify = bodyscan("archive " + quote(archive) + " verify", dir);
  ASSERT_EQ(verify.exit_code, 0) << verify.err;
  const CliResult list = bodyscan("archive " + quote(archive) + " list", dir);
  std::istringstream lines(list.out);
  std::string line;
  size_t complete = 0, failed = 0;
  while (std::getline(lines, line)) {
    complete += line.find(" complete ") != std::string::npos;
    if (line.find(" failed ") != std::string::npos) {
      ++failed;
      EXPECT_NE(line.find("interrupted"), std::string::npos) << line;
    }
  }
  EXPECT_EQ(complete, 1u) << list.out;
  // Each kill lands 2.1 or 2.4 s in, well after the scan is recorded as running
  // (under 1.5 s even on a loaded machine); allow for a slower start all the same.
  EXPECT_GE(failed, 1u) << list.out;
  EXPECT_LE(failed, 2u) << list.out;
}

TEST(ArchiveCli, SheetExportAndErasure) {
  const std::string dir = testing::temp_dir();
  std::string customer, scan;
  {
    auto ar = storage::Archive::open(dir + "/A");
    ASSERT_TRUE(ar.ok());
    auto mesh = read_ply_mesh(BODYSCAN_SOURCE_DIR "/hw/sim/bodies/female_average.ply");
    ASSERT_TRUE(mesh.ok());
    auto body = measure_body(*mesh);
    ASSERT_TRUE(body.ok());
    customer = (*ar)->add_customer("Zora Quintrell", "zora@example.org", "op")->id;
    scan = *(*ar)->begin_scan(customer, "op", {{"name", "thesis"}}, "");
    storage::ScanResults results;
    storage::DracoOptions keep;
    keep.max_error_mm = 0.01;
    results.files["mesh.drc"] = storage::encode_mesh_drc(*mesh, keep)->bytes;
    for (const BodyMeasurement& m : body->measurements) {
      storage::MeasurementRecord rec;
      rec.name = m.name, rec.label = m.label, rec.kind = m.kind, rec.iso_clause = m.iso_clause,
      rec.value_mm = m.value_mm;
      results.measurements.push_back(rec);
    }
    ASSERT_TRUE((*ar)->complete_scan(scan, results).ok());
  }
  const std::string A = quote(dir + "/A");
  const CliResult csv =
      bodyscan("archive " + A + " sheet " + scan + " -o " + quote(dir + "/s.csv") + " --unit mm", dir);
  ASSERT_EQ(csv.exit_code, 0) << csv.err;
  EXPECT_NE(slurp(dir + "/s.csv").find("5.3.10,waist_girth,Waist girth,"), std::string::npos);
  const CliResult pdf = bodyscan("archive " + A + " sheet " + scan + " -o " + quote(dir + "/s.pdf"), dir);
  ASSERT_EQ(pdf.exit_code, 0) << pdf.err;
  EXPECT_EQ(slurp(dir + "/s.pdf").rfind("%PDF-", 0), 0u);

  for (const char* ext : {"ply", "obj", "stl", "glb"}) {
    const std::string file = dir + "/m." + ext;
    const CliResult m = bodyscan("archive " + A + " mesh " + scan + " -o " + quote(file), dir);
    ASSERT_EQ(m.exit_code, 0) << ext << ": " << m.err;
    EXPECT_NE(m.out.find("107024 triangles"), std::string::npos) << m.out;
  }
  auto ply = read_ply_mesh(dir + "/m.ply");
  ASSERT_TRUE(ply.ok());
  EXPECT_EQ(ply->num_triangles(), 107024u);
  EXPECT_EQ(std::filesystem::file_size(dir + "/m.stl"), 84 + 50 * 107024u);
  EXPECT_EQ(bodyscan("archive " + A + " mesh " + scan + " -o " + quote(dir + "/m.docx"), dir).exit_code, 2);

  const CliResult exported =
      bodyscan("archive " + A + " export " + customer + " " + quote(dir + "/X") + " --actor admin", dir);
  ASSERT_EQ(exported.exit_code, 0) << exported.err;
  EXPECT_NE(slurp(dir + "/X/customer.json").find("Zora Quintrell"), std::string::npos);

  const CliResult unsure = bodyscan("archive " + A + " erase " + customer, dir);
  EXPECT_EQ(unsure.exit_code, 2);
  EXPECT_NE(unsure.err.find("--yes"), std::string::npos) << unsure.err;
  const CliResult erased = bodyscan("archive " + A + " erase " + customer + " --yes --actor admin", dir);
  ASSERT_EQ(erased.exit_code, 0) << erased.err;
  EXPECT_EQ(bodyscan("archive " + A + " list", dir).out, "");
  const CliResult gone = bodyscan("archive " + A + " show " + scan, dir);
  EXPECT_EQ(gone.exit_code, 1);
  EXPECT_NE(gone.err.find("no scan"), std::string::npos) << gone.err;
  EXPECT_EQ(bodyscan("archive " + A + " frobnicate", dir).exit_code, 2);
  EXPECT_EQ(bodyscan("archive", dir).exit_code, 2);
}

}  // namespace
}  // namespace bodyscan
