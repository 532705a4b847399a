#include "hw/safety.hpp"

#include <signal.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <exception>
#include <mutex>

namespace bodyscan::hw {

namespace {

constexpr int kSlots = 16;
struct Slot {
  std::atomic<EmergencyStopFn> fn{nullptr};
  std::atomic<void*> context{nullptr};
};
Slot g_slots[kSlots];
std::mutex g_register_mutex;
std::atomic<bool> g_installed{false};
std::terminate_handler g_previous_terminate = nullptr;

static_assert(std::atomic<EmergencyStopFn>::is_always_lock_free, "the signal path needs lock-free atomics");

// 0 until a handler starts the stops, 1 while it runs them, 2 after.
std::atomic<int> g_stopping{0};

// Runs the stops once per process. A thread that comes second (two threads
// crashing, a signal during a crash) waits, up to a second, for the first to
// finish, so that its own death does not end the process half way through them.
void run_emergency_stops_once() noexcept {
  int none = 0;
  if (g_stopping.compare_exchange_strong(none, 1)) {
    run_emergency_stops();
    g_stopping.store(2);
    return;
  }
  for (int ms = 0; ms < 1000 && g_stopping.load() != 2; ++ms) {
    const timespec one_ms{0, 1000000};
    nanosleep(&one_ms, nullptr);
  }
}

void on_signal(int sig) {
  run_emergency_stops_once();
  // Let the signal do what it would have done (core dump, exit status).
  signal(sig, SIG_DFL);
  raise(sig);
}

[[noreturn]] void on_terminate() {
  run_emergency_stops_once();
  if (g_previous_terminate) g_previous_terminate();
  std::abort();
}

// An mmap'd alternate signal stack with a guard page below it, so that a handler
// overrunning it faults rather than writing over whatever lies below.
class AlternateStack {
 public:
  AlternateStack() {
    stack_t current{};
    if (sigaltstack(nullptr, &current) == 0 && !(current.ss_flags & SS_DISABLE)) {
      present_ = true;  // the thread has one already: keep it
      return;
    }
    const auto page = static_cast<size_t>(sysconf(_SC_PAGESIZE));
    // The handlers need little (a few system calls); the kernel's signal frame
    // grows with the CPU's register state, which _SC_MINSIGSTKSZ reports.
    size_t size = 64 * 1024;
    const long min_frame = sysconf(_SC_MINSIGSTKSZ);
    if (min_frame > 0) size = std::max(size, 4 * static_cast<size_t>(min_frame));
    size = (size + page - 1) / page * page;
    void* m = mmap(nullptr, size + page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_STACK, -1, 0);
    if (m == MAP_FAILED) return;
    mprotect(m, page, PROT_NONE);
    stack_t ss{};
    ss.ss_sp = static_cast<char*>(m) + page;
    ss.ss_size = size;
    if (sigaltstack(&ss, nullptr) != 0) {
      munmap(m, size + page);
      return;
    }
    memory_ = m;
    mapped_ = size + page;
    present_ = true;
  }
  ~AlternateStack() {
    if (memory_ == nullptr) return;
    stack_t off{};
    off.ss_flags = SS_DISABLE;
    sigaltstack(&off, nullptr);
    munmap(memory_, mapped_);
  }
  AlternateStack(const AlternateStack&) = delete;
  AlternateStack& operator=(const AlternateStack&) = delete;
  bool present() const { return present_; }

 private:
  void* memory_ = nullptr;
  size_t mapped_ = 0;
  bool present_ = false;
};

}  // namespace

int register_emergency_stop(EmergencyStopFn fn, void* context) {
  std::lock_guard lock(g_register_mutex);
  for (int i = 0; i < kSlots; ++i) {
    if (g_slots[i].fn.load() == nullptr) {
      g_slots[i].context.store(context);
      g_slots[i].fn.store(fn);
      return i;
    }
  }
  return -1;
}

void unregister_emergency_stop(int slot) {
  if (slot < 0 || slot >= kSlots) return;
  std::lock_guard lock(g_register_mutex);
  g_slots[slot].fn.store(nullptr);
  g_slots[slot].context.store(nullptr);
}

void run_emergency_stops() noexcept {
  for (Slot& s : g_slots) {
    const EmergencyStopFn fn = s.fn.load();
    if (fn) fn(s.context.load());
  }
}

bool ensure_alternate_signal_stack() {
  thread_local AlternateStack stack;
  return stack.present();
}

void install_laser_safety_handlers(bool termination_signals) {
  if (g_installed.exchange(true)) return;
  // The installing thread (usually the main thread) keeps its stack until the
  // process ends, past the destruction of thread_local objects at exit.
  static AlternateStack* const kept = new AlternateStack;
  (void)kept;
  constexpr int kCrashSignals[] = {SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGABRT};
  constexpr int kTerminationSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  // The others wait while a handler runs: the stops run once, on one stack.
  sigemptyset(&sa.sa_mask);
  for (int sig : kCrashSignals) sigaddset(&sa.sa_mask, sig);
  for (int sig : kTerminationSignals) sigaddset(&sa.sa_mask, sig);
  // SA_RESETHAND: a second fault in the handler ends the process.
  sa.sa_flags = SA_RESETHAND | SA_ONSTACK;
  for (int sig : kCrashSignals) sigaction(sig, &sa, nullptr);
  if (termination_signals) {
    for (int sig : kTerminationSignals) sigaction(sig, &sa, nullptr);
  }
  g_previous_terminate = std::set_terminate(on_terminate);
}

}  // namespace bodyscan::hw
