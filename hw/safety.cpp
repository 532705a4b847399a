#include "hw/safety.hpp"

#include <signal.h>
#include <unistd.h>

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

void on_signal(int sig) {
  run_emergency_stops();
  // Let the signal do what it would have done (core dump, exit status).
  signal(sig, SIG_DFL);
  raise(sig);
}

[[noreturn]] void on_terminate() {
  run_emergency_stops();
  if (g_previous_terminate) g_previous_terminate();
  std::abort();
}

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

void install_laser_safety_handlers(bool termination_signals) {
  if (g_installed.exchange(true)) return;
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND;  // a second fault in the handler ends the process
  for (int sig : {SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGABRT}) sigaction(sig, &sa, nullptr);
  if (termination_signals) {
    for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) sigaction(sig, &sa, nullptr);
  }
  g_previous_terminate = std::set_terminate(on_terminate);
}

}  // namespace bodyscan::hw
