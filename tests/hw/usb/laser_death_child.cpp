// The process the laser-safety tests kill (tests/hw/usb/laser_safety_test.cpp):
//
//   laser_death_child PORT WATCHDOG_MS DEATH READY_FD GO_FD
//
// Installs the laser-safety handlers, opens the TMCL board on PORT, switches laser
// 0 on, writes one byte to READY_FD, waits for one byte on GO_FD (the test has seen
// the laser on) and then dies as DEATH says. It is a program of its own, started
// by fork and exec, so that it begins as a fresh process: a child that ran on
// after a bare fork of the multi-threaded test process could hang on a lock that
// another of the parent's threads held at the fork (an allocator's, under the
// sanitizers), before it ever reached the death under test.
// Exit status 2: bad arguments; 3: the board could not be opened or the laser
// switched on.
#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <optional>
#include <string>
#include <thread>

#include "hw/safety.hpp"
#include "hw/usb/tmcl_controller.hpp"
#include "tests/deaths.hpp"
#include "tests/hw/usb/laser_deaths.hpp"
#include "tests/hw/usb/tmcl_rig.hpp"

namespace {

using bodyscan::hw::testing::Death;
using bodyscan::testing::overflow_stack;

// No core files; and a main-thread stack that overflows at 8 MiB even where the
// limit is larger or unlimited.
void limit_resources() {
  const rlimit no_core{0, 0};
  setrlimit(RLIMIT_CORE, &no_core);
  rlimit stack{};
  if (getrlimit(RLIMIT_STACK, &stack) == 0 && stack.rlim_cur > (8u << 20)) {
    stack.rlim_cur = 8u << 20;
    setrlimit(RLIMIT_STACK, &stack);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 6) {
    std::fprintf(stderr, "usage: laser_death_child PORT WATCHDOG_MS DEATH READY_FD GO_FD\n");
    return 2;
  }
  const std::string port = argv[1];
  const int watchdog_ms = std::atoi(argv[2]);
  const std::optional<Death> death = bodyscan::hw::testing::parse_death(argv[3]);
  const int ready = std::atoi(argv[4]);
  const int go = std::atoi(argv[5]);
  if (!death) {
    std::fprintf(stderr, "laser_death_child: no death called '%s'\n", argv[3]);
    return 2;
  }
  limit_resources();
  bodyscan::hw::install_laser_safety_handlers(true);
  auto c = bodyscan::hw::usb::TmclController::open(bodyscan::hw::testing::tmcl_rig(port, watchdog_ms));
  if (!c.ok()) return 3;
  auto switch_on_and_wait = [&] {
    if (!(*c)->set_laser(0, true).ok()) std::_Exit(3);
    const char one = 1;
    (void)!write(ready, &one, 1);
    char wait_for_parent = 0;
    (void)!read(go, &wait_for_parent, 1);
  };
  if (*death == Death::kStackOverflowOnRigThread) {
    // The thread that switched the laser on overflows.
    std::thread([&] {
      switch_on_and_wait();
      overflow_stack(0);
    }).join();
  } else if (*death == Death::kStackOverflowOnOtherThread) {
    // A thread that never touched the rig, but asked for an alternate stack.
    switch_on_and_wait();
    std::thread([] {
      bodyscan::hw::ensure_alternate_signal_stack();
      overflow_stack(0);
    }).join();
  } else {
    switch_on_and_wait();
  }
  if (*death == Death::kSegfault) raise(SIGSEGV);
  if (*death == Death::kAbort) std::abort();
  if (*death == Death::kTerminate) std::terminate();
  if (*death == Death::kStackOverflow) overflow_stack(0);
  for (;;) pause();  // the signal deaths: the test sends the signal
}
