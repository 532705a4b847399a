// The workstation on its own (no HTTP): what it finds in a data folder at start,
// and a calibration that waits for the person holding the dot grid.
#include <gtest/gtest.h>
#include <sodium.h>

#include <chrono>
#include <cstdlib>
#include <thread>

#include "server/workstation/workstation.hpp"
#include "tests/half_resolution.hpp"
#include "tests/test_data.hpp"

namespace bodyscan::testing {
namespace {

// A scan stored by `bodyscan scan --archive` carries its calibration in its raw
// record: a workstation opened on that archive starts calibrated with it (for
// the same rig only), so the demo's server needs no calibration before its first
// scan.
TEST(Workstation, StartsWithTheCalibrationOfTheNewestArchivedScanOnThisRig) {
  const std::string data = temp_dir();
  const std::string rig_file = half_resolution_rig_file();
  const std::string cmd = std::string(BODYSCAN_BIN) + " scan --rig '" + rig_file +
                          "' --every 12 --no-surface -q --archive '" + data + "' --new-customer Demo > /dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  server::WorkstationOptions o;
  o.data_dir = data;
  o.rig = rig_file;
  o.auth.opslimit = crypto_pwhash_OPSLIMIT_MIN;
  o.auth.memlimit = crypto_pwhash_MEMLIMIT_MIN;
  std::string scan_calibration;
  {
    auto ws = server::Workstation::open(o);
    ASSERT_TRUE(ws.ok()) << ws.status().message();
    auto scans = (*ws)->archive().scans();
    ASSERT_TRUE(scans.ok());
    ASSERT_EQ(scans->size(), 1u);
    scan_calibration = (*scans)[0].calibration_id;
    ASSERT_FALSE(scan_calibration.empty());
    const nlohmann::json rig = (*ws)->rig_status();
    ASSERT_TRUE(rig["calibration"].is_object()) << rig.dump();
    EXPECT_EQ(rig["calibration"]["id"], scan_calibration);
    EXPECT_EQ(rig["calibration"]["cameras"].size(), 3u);
    EXPECT_LT(rig["calibration"]["age_s"].get<int64_t>(), 600);
  }
  // Another rig does not inherit it.
  o.rig = "square";
  auto other = server::Workstation::open(o);
  ASSERT_TRUE(other.ok()) << other.status().message();
  EXPECT_TRUE((*other)->rig_status()["calibration"].is_null());
}

server::WorkstationOptions training_options() {
  server::WorkstationOptions o;
  o.data_dir = temp_dir();
  o.rig = half_resolution_rig_file();
  o.auth.opslimit = crypto_pwhash_OPSLIMIT_MIN;
  o.auth.memlimit = crypto_pwhash_MEMLIMIT_MIN;
  o.operator_dot_grid = true;
  return o;
}

// The job's prompt once it asks something other than `after` (waits up to 60 s).
std::optional<server::JobPrompt> next_prompt(server::Workstation& ws, const std::string& job,
                                             const std::string& after = "") {
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < until) {
    auto j = ws.job(job);
    if (!j || j->state != server::JobState::kRunning) return std::nullopt;
    if (j->prompt && j->prompt->id != after) return j->prompt;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return std::nullopt;
}

// Staff training on the simulated rig: the calibration waits for the person to
// say the board is before each camera, then that the rig is clear; the events
// carry each prompt; an answer to an old prompt is refused.
TEST(Workstation, CalibrationWaitsForThePersonHoldingTheDotGrid) {
  const server::WorkstationOptions o = training_options();
  auto ws = server::Workstation::open(o);
  ASSERT_TRUE(ws.ok()) << ws.status().message();
  std::mutex m;
  std::vector<nlohmann::json> prompts;  // as the events showed them
  (*ws)->subscribe([&](std::shared_ptr<const std::string> text) {
    const nlohmann::json e = nlohmann::json::parse(*text);
    if (e["type"] != "job") return;
    ASSERT_TRUE(e["job"].contains("prompt")) << e.dump();
    std::lock_guard lock(m);
    if (e["job"]["prompt"].is_object() && (prompts.empty() || prompts.back()["id"] != e["job"]["prompt"]["id"]))
      prompts.push_back(e["job"]["prompt"]);
  });
  auto job = (*ws)->start_calibration("olivia");
  ASSERT_TRUE(job.ok()) << job.status().message();
  EXPECT_EQ((*ws)->answer_prompt("j_nope", "p1").code(), StatusCode::kNotFound);
  std::vector<server::JobPrompt> asked;
  std::string last;
  while (auto p = next_prompt(**ws, job->id, last)) {
    if (!last.empty()) {
      const Status old = (*ws)->answer_prompt(job->id, last);
      EXPECT_EQ(old.code(), StatusCode::kFailedPrecondition) << old.message();
    }
    asked.push_back(*p);
    last = p->id;
    // Nothing moves while the person is asked: every laser off.
    hw::Controller& ctl = (*ws)->simulated_rig()->controller();
    for (int i = 0; i < ctl.num_lasers(); ++i) EXPECT_FALSE(ctl.laser_on(i)) << i;
    ASSERT_TRUE((*ws)->answer_prompt(job->id, p->id).ok());
  }
  ASSERT_TRUE((*ws)->wait_idle(120));
  const auto done = (*ws)->job(job->id);
  ASSERT_TRUE(done);
  ASSERT_EQ(done->state, server::JobState::kComplete) << done->error;
  EXPECT_FALSE(done->prompt);
  EXPECT_EQ((*ws)->answer_prompt(job->id, last).code(), StatusCode::kFailedPrecondition);
  const nlohmann::json rig = (*ws)->rig_status();
  ASSERT_TRUE(rig["calibration"].is_object()) << rig.dump();
  ASSERT_EQ(asked.size(), rig["cameras"].size() + 1);
  for (size_t i = 0; i + 1 < asked.size(); ++i) {
    EXPECT_EQ(asked[i].kind, "hold_dot_grid");
    EXPECT_EQ(asked[i].camera, rig["cameras"][i]["id"]);
    EXPECT_NE(asked[i].text.find(asked[i].camera), std::string::npos) << asked[i].text;
    EXPECT_TRUE(asked[i].why.empty()) << asked[i].why;
  }
  EXPECT_EQ(asked.back().kind, "remove_dot_grid");
  EXPECT_TRUE(asked.back().camera.empty());
  std::lock_guard lock(m);
  ASSERT_EQ(prompts.size(), asked.size());
  for (size_t i = 0; i < asked.size(); ++i) {
    EXPECT_EQ(prompts[i]["id"], asked[i].id);
    EXPECT_EQ(prompts[i]["kind"], asked[i].kind);
    EXPECT_EQ(prompts[i]["text"], asked[i].text);
  }
}

// Cancelled while it waits for the person: the job ends at once, lasers off.
TEST(Workstation, CancellingAWaitingCalibrationEndsIt) {
  auto ws = server::Workstation::open(training_options());
  ASSERT_TRUE(ws.ok()) << ws.status().message();
  auto job = (*ws)->start_calibration("olivia");
  ASSERT_TRUE(job.ok()) << job.status().message();
  auto p = next_prompt(**ws, job->id);
  ASSERT_TRUE(p);
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE((*ws)->cancel(job->id, "olivia").ok());
  ASSERT_TRUE((*ws)->wait_idle(10));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 2.0);
  const auto done = (*ws)->job(job->id);
  ASSERT_TRUE(done);
  EXPECT_EQ(done->state, server::JobState::kCancelled);
  EXPECT_NE(done->error.find("olivia"), std::string::npos) << done->error;
  EXPECT_FALSE(done->prompt);
  EXPECT_EQ((*ws)->answer_prompt(job->id, p->id).code(), StatusCode::kFailedPrecondition);
  const nlohmann::json rig = (*ws)->rig_status();  // held: a range-for does not keep a temporary's member alive
  for (const auto& l : rig["lasers"]) EXPECT_FALSE(l["on"].get<bool>());
  EXPECT_TRUE((*ws)->rig_status()["calibration"].is_null());
}

// Nobody answers: the calibration stops after the timeout, saying so.
TEST(Workstation, AnUnansweredPromptTimesOut) {
  server::WorkstationOptions o = training_options();
  o.operator_timeout_s = 0.5;
  auto ws = server::Workstation::open(o);
  ASSERT_TRUE(ws.ok()) << ws.status().message();
  auto job = (*ws)->start_calibration("olivia");
  ASSERT_TRUE(job.ok()) << job.status().message();
  ASSERT_TRUE((*ws)->wait_idle(30));
  const auto done = (*ws)->job(job->id);
  ASSERT_TRUE(done);
  EXPECT_EQ(done->state, server::JobState::kFailed);
  EXPECT_NE(done->error.find("nobody confirmed"), std::string::npos) << done->error;
  EXPECT_FALSE(done->prompt);
  const nlohmann::json rig = (*ws)->rig_status();  // held: a range-for does not keep a temporary's member alive
  for (const auto& l : rig["lasers"]) EXPECT_FALSE(l["on"].get<bool>());
}

}  // namespace
}  // namespace bodyscan::testing
