// A scan that dies with its laser on. A forked child opens the rig of
// tmcl_board_scan_test.cpp (the simulated TMCL board behind a pseudo-terminal, its
// watchdog at a minute, simulated cameras) and runs the scan's acquisition on a
// job thread, as the workstation does; at the first scan shot, lasers on, it
// dies: a stack overflow or a fault on the job thread, an abort, or a SIGHUP from
// outside. The board, here in the parent, must see every laser off soon after -
// the process's emergency stop, since the watchdog would take a minute.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <thread>

#include "hw/device_rig.hpp"
#include "hw/safety.hpp"
#include "hw/usb/sim_tmcl_board.hpp"
#include "pipeline/acquire.hpp"
#include "pipeline/rig_backend.hpp"
#include "tests/deaths.hpp"
#include "tests/half_resolution.hpp"
#include "tests/hw/usb/tmcl_rig.hpp"

namespace bodyscan::pipeline {
namespace {

using namespace std::chrono_literals;

enum class Death { kStackOverflow, kSegfault, kAbort, kSighup };

using bodyscan::testing::overflow_stack;

// A store through a pointer the compiler cannot see is null: a real fault, not a
// trap instruction put in its place.
int* volatile g_nowhere = nullptr;

[[noreturn]] void child(const hw::RigDescription& desc, Death death, int ready, int go) {
  const rlimit no_core{0, 0};
  setrlimit(RLIMIT_CORE, &no_core);
  hw::install_laser_safety_handlers(true);
  auto devices = hw::DeviceRig::open(desc);
  if (!devices.ok()) _exit(3);
  const Rig rig = rig_handle(**devices);
  bool died = false;
  const ShotSink sink = [&](Shot&& shot) -> Status {
    if (shot.kind != ShotKind::kScanStep || died) return Status::Ok();
    died = true;
    const char one = 1;
    (void)!write(ready, &one, 1);
    char byte = 0;
    (void)!read(go, &byte, 1);  // until the parent has seen the laser on
    switch (death) {
      case Death::kStackOverflow: overflow_stack(0); break;
      case Death::kSegfault: *g_nowhere = 1; break;
      case Death::kAbort: std::abort();
      case Death::kSighup: break;
    }
    for (;;) pause();  // the parent signals it
  };
  std::thread job([&] { (void)acquire_scan(rig, sink, /*every=*/8); });
  job.join();
  _exit(4);  // the scan ended without a scan shot
}

std::string death_name(const ::testing::TestParamInfo<std::pair<Death, int>>& p) {
  static const char* const names[] = {"StackOverflow", "Segfault", "Abort", "Sighup"};
  return names[static_cast<int>(p.param.first)];
}

class ScanCrash : public ::testing::TestWithParam<std::pair<Death, int>> {};

TEST_P(ScanCrash, EveryLaserIsOffWhenTheScanDies) {
  const auto [death, expected_signal] = GetParam();
  hw::usb::SimTmclBoard board(1, {5000, -4000, 2500, -1200, 0, 0});
  board.set_speed(400000);
  auto pty = hw::usb::PtyBoard::start(board);
  ASSERT_TRUE(pty.ok());
  hw::RigDescription desc = hw::testing::tmcl_rig((*pty)->path(), 60000);
  testing::halve_resolution(desc);

  int ready[2], go[2];
  ASSERT_EQ(pipe(ready), 0);
  ASSERT_EQ(pipe(go), 0);
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    close(ready[0]);
    close(go[1]);
    child(desc, death, ready[1], go[0]);
  }
  close(ready[1]);
  close(go[0]);
  char byte = 0;
  const bool scanning = read(ready[0], &byte, 1) == 1;
  close(ready[0]);
  bool any_on = false;
  for (const auto& w : desc.controller.lasers) any_on = any_on || board.output(w.output);
  (void)!write(go[1], &byte, 1);
  close(go[1]);
  if (death == Death::kSighup) kill(pid, SIGHUP);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(scanning) << "the child never reached a scan shot, status " << status;
  ASSERT_TRUE(any_on) << "no laser was on at the scan shot";
  ASSERT_TRUE(WIFSIGNALED(status)) << "the child should die of its signal, status " << status;
  EXPECT_EQ(WTERMSIG(status), expected_signal);

  const auto t0 = std::chrono::steady_clock::now();
  auto all_off = [&] {
    for (const auto& w : desc.controller.lasers)
      if (board.output(w.output)) return false;
    return true;
  };
  while (!all_off() && std::chrono::steady_clock::now() - t0 < 500ms) std::this_thread::sleep_for(1ms);
  for (const auto& w : desc.controller.lasers) EXPECT_FALSE(board.output(w.output)) << "output " << w.output;
  EXPECT_EQ(board.watchdog_trips(), 0);
}

INSTANTIATE_TEST_SUITE_P(MidScan, ScanCrash,
                         ::testing::Values(std::pair{Death::kStackOverflow, SIGSEGV},
                                           std::pair{Death::kSegfault, SIGSEGV}, std::pair{Death::kAbort, SIGABRT},
                                           std::pair{Death::kSighup, SIGHUP}),
                         death_name);

}  // namespace
}  // namespace bodyscan::pipeline
