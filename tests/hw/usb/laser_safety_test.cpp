// Laser safety on every failure path the simulation can produce, each in a child
// process (tests/hw/usb/laser_death_child.cpp) that opens the rig's TMCL controller over a pseudo-terminal, switches a
// laser on and then dies a different way. The board (here, in the parent) must
// see the laser off:
// - by the process's own emergency stop (crash signals, a stack overflow on the
//   main thread or another, std::terminate, SIGTERM, SIGINT, SIGHUP) - with the
//   board's watchdog set to a minute, so only that path can have done it, and fast;
// - by the board's watchdog when nothing in the process can run (SIGKILL).
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <iterator>
#include <string>
#include <thread>

#include "hw/controller.hpp"
#include "hw/safety.hpp"
#include "hw/usb/serial_link.hpp"
#include "hw/usb/sim_tmcl_board.hpp"
#include "hw/usb/tmcl_controller.hpp"
#include "tests/hw/usb/laser_deaths.hpp"
#include "tests/hw/usb/tmcl_rig.hpp"

namespace bodyscan::hw::usb {
namespace {

using namespace std::chrono_literals;

using testing::Death;

// Starts the child (fork, then only exec in it: this process has threads), waits
// up to a minute for it to switch the laser on, lets it die and returns its wait
// status. `laser_output` is the board output of laser 0.
int run_child(const std::string& port, int watchdog_ms, Death death, SimTmclBoard& board, int laser_output,
              bool* was_on) {
  int ready[2], go[2];
  if (pipe(ready) != 0 || pipe(go) != 0) return -1;
  const std::string args[] = {LASER_DEATH_CHILD,           port,
                              std::to_string(watchdog_ms), testing::death_name(death),
                              std::to_string(ready[1]),    std::to_string(go[0])};
  char* argv[std::size(args) + 1] = {};
  for (size_t i = 0; i < std::size(args); ++i) argv[i] = const_cast<char*>(args[i].c_str());
  const pid_t pid = fork();
  if (pid == 0) {
    close(ready[0]);
    close(go[1]);
    execv(argv[0], argv);
    _exit(127);
  }
  close(ready[1]);
  close(go[0]);
  char byte = 0;
  pollfd p{ready[0], POLLIN, 0};
  const bool started = pid > 0 && poll(&p, 1, 60000) == 1 && read(ready[0], &byte, 1) == 1;
  close(ready[0]);
  *was_on = started && board.output(laser_output);
  if (started) {
    (void)!write(go[1], &byte, 1);
  } else if (pid > 0) {
    kill(pid, SIGKILL);
  }
  close(go[1]);
  if (pid <= 0) return -1;
  if (started && death == Death::kSigterm) kill(pid, SIGTERM);
  if (started && death == Death::kSigint) kill(pid, SIGINT);
  if (started && death == Death::kSigkill) kill(pid, SIGKILL);
  if (started && death == Death::kSighup) kill(pid, SIGHUP);
  int status = 0;
  waitpid(pid, &status, 0);
  return status;
}

// How long after the child's death the laser output went off; -1 if not within `limit`.
double off_within(SimTmclBoard& board, int output, std::chrono::milliseconds limit) {
  const auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - t0 < limit) {
    if (!board.output(output))
      return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::this_thread::sleep_for(1ms);
  }
  return -1;
}

std::string death_name(const ::testing::TestParamInfo<std::pair<Death, int>>& p) {
  static const char* const names[] = {"Segfault",
                                      "Abort",
                                      "Terminate",
                                      "Sigterm",
                                      "Sigint",
                                      "Sigkill",
                                      "Sighup",
                                      "StackOverflow",
                                      "StackOverflowOnTheRigThread",
                                      "StackOverflowOnAnotherThread"};
  return names[static_cast<int>(p.param.first)];
}

class LaserSafety : public ::testing::TestWithParam<std::pair<Death, int>> {};

TEST_P(LaserSafety, LaserGoesOffWhenTheProcessDies) {
  const auto [death, expected_signal] = GetParam();
  SimTmclBoard board;
  auto pty = PtyBoard::start(board);
  ASSERT_TRUE(pty.ok());
  const int output = testing::tmcl_rig((*pty)->path(), 0).controller.lasers[0].output;
  const bool uncatchable = death == Death::kSigkill;
  bool was_on = false;
  const int status = run_child((*pty)->path(), uncatchable ? 300 : 60000, death, board, output, &was_on);
  ASSERT_TRUE(was_on) << "the child never switched the laser on, status " << status;
  ASSERT_TRUE(WIFSIGNALED(status)) << "the child should die of its signal, status " << status;
  EXPECT_EQ(WTERMSIG(status), expected_signal);
  if (uncatchable) {
    // Only the board's watchdog can do it: within its period plus a feed interval.
    const double ms = off_within(board, output, 1500ms);
    EXPECT_GE(ms, 0) << "the board's watchdog did not switch the laser off";
    EXPECT_GE(board.watchdog_trips(), 1);
  } else {
    const double ms = off_within(board, output, 500ms);
    EXPECT_GE(ms, 0) << "the emergency stop did not switch the laser off";
    EXPECT_EQ(board.watchdog_trips(), 0);
  }
}

INSTANTIATE_TEST_SUITE_P(EveryDeath, LaserSafety,
                         ::testing::Values(std::pair{Death::kSegfault, SIGSEGV}, std::pair{Death::kAbort, SIGABRT},
                                           std::pair{Death::kTerminate, SIGABRT}, std::pair{Death::kSigterm, SIGTERM},
                                           std::pair{Death::kSigint, SIGINT}, std::pair{Death::kSigkill, SIGKILL},
                                           std::pair{Death::kSighup, SIGHUP}, std::pair{Death::kStackOverflow, SIGSEGV},
                                           std::pair{Death::kStackOverflowOnRigThread, SIGSEGV},
                                           std::pair{Death::kStackOverflowOnOtherThread, SIGSEGV}),
                         death_name);

TEST(LaserSafetyInProcess, ExceptionUnwindingThroughLasersOff) {
  SimTmclBoard board;
  auto pty = PtyBoard::start(board);
  ASSERT_TRUE(pty.ok());
  const RigDescription rig = testing::tmcl_rig((*pty)->path(), 0);
  auto c = TmclController::open(rig);
  ASSERT_TRUE(c.ok());
  try {
    LasersOff guard(**c);
    ASSERT_TRUE((*c)->set_laser(1, true).ok());
    ASSERT_TRUE(board.output(rig.controller.lasers[1].output));
    throw std::runtime_error("a stage failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_FALSE(board.output(rig.controller.lasers[1].output));
}

// The emergency stop after the normal path has put only the first `cut` bytes of
// a frame on the wire (here a frame switching laser 1 on): the board must refuse
// the completed frame for its checksum, then run exactly the off frames.
void expect_resynchronised(SimTmclBoard& board, const RigDescription& rig, size_t cut, uint64_t ran_before,
                           uint64_t refused_before) {
  const auto& wiring = rig.controller.lasers;
  EXPECT_EQ(board.checksum_errors(), refused_before + (cut > 0 ? 1 : 0))
      << "the half-sent frame was not completed as a frame the board refuses";
  ASSERT_EQ(board.executed_count(), ran_before + wiring.size())
      << "the board ran something besides the off frames (a frame assembled from the cut one and the stop's bytes)";
  const std::vector<tmcl::Request> last = board.last_executed(wiring.size());
  for (size_t i = 0; i < wiring.size(); ++i) {
    EXPECT_EQ(last[i].command, tmcl::kSIO);
    EXPECT_EQ(last[i].type, wiring[i].output);
    EXPECT_EQ(last[i].bank, tmcl::kBankOutputs);
    EXPECT_EQ(last[i].value, 0);
    EXPECT_FALSE(board.output(wiring[i].output)) << "laser " << i;
  }
}

tmcl::Frame laser_on_frame(const RigDescription& rig, int laser) {
  return tmcl::encode(tmcl::Request{static_cast<uint8_t>(rig.controller.module_address), tmcl::kSIO,
                                    static_cast<uint8_t>(rig.controller.lasers[static_cast<size_t>(laser)].output),
                                    tmcl::kBankOutputs, 1});
}

TEST(EmergencyStopResync, CompletesAHalfSentFrameAtEveryCut) {
  for (size_t cut = 0; cut < 9; ++cut) {
    SCOPED_TRACE("frame cut after " + std::to_string(cut) + " bytes");
    SimTmclBoard board;
    auto owned = std::make_unique<SimBoardLink>(board);
    SimBoardLink* link = owned.get();
    const RigDescription rig = testing::tmcl_rig("in process", 0);
    auto c = TmclController::open(rig, std::move(owned));
    ASSERT_TRUE(c.ok()) << c.status().message();
    ASSERT_TRUE((*c)->set_laser(0, true).ok());
    const tmcl::Frame on = laser_on_frame(rig, 1);
    ASSERT_TRUE(link->write(on.data(), cut, std::chrono::milliseconds(0)).ok());
    const uint64_t ran = board.executed_count(), refused = board.checksum_errors();

    run_emergency_stops();
    expect_resynchronised(board, rig, cut, ran, refused);

    // The stop keeps the link: nothing switches a laser on behind it.
    const Status again = (*c)->set_laser(1, true);
    EXPECT_EQ(again.code(), StatusCode::kUnavailable) << again.message();
    EXPECT_FALSE(board.output(rig.controller.lasers[1].output));
  }
}

TEST(EmergencyStopResync, CompletesAHalfSentFrameOnASerialPort) {
  SimTmclBoard board;
  auto pty = PtyBoard::start(board);
  ASSERT_TRUE(pty.ok());
  const RigDescription rig = testing::tmcl_rig((*pty)->path(), 0);
  auto owned = SerialLink::open((*pty)->path());
  ASSERT_TRUE(owned.ok()) << owned.status().message();
  SerialLink* link = owned->get();
  auto c = TmclController::open(rig, std::move(*owned));
  ASSERT_TRUE(c.ok()) << c.status().message();
  ASSERT_TRUE((*c)->set_laser(0, true).ok());
  const tmcl::Frame on = laser_on_frame(rig, 1);
  const size_t cut = 5;
  ASSERT_TRUE(link->write(on.data(), cut, std::chrono::milliseconds(200)).ok());
  const uint64_t ran = board.executed_count(), refused = board.checksum_errors();

  run_emergency_stops();
  // The board takes the bytes from the pseudo-terminal on its own thread.
  const size_t expected = rig.controller.lasers.size();
  const auto t0 = std::chrono::steady_clock::now();
  while (board.executed_count() < ran + expected && std::chrono::steady_clock::now() - t0 < 2s) {
    std::this_thread::sleep_for(1ms);
  }
  expect_resynchronised(board, rig, cut, ran, refused);
}

}  // namespace
}  // namespace bodyscan::hw::usb
