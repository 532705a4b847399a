#include "hw/usb/byte_link.hpp"

#include <time.h>

#include <cstring>

namespace bodyscan::hw::usb {

namespace {

// Every signal but those a fault raises on the faulting thread itself (blocking
// them leaves a fault undefined) and those that cannot be blocked.
sigset_t asynchronous_signals() {
  sigset_t set;
  sigfillset(&set);
  for (int sig : {SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGTRAP, SIGSYS}) sigdelset(&set, sig);
  return set;
}

}  // namespace

WireLedger::Send::Send(WireLedger& ledger) noexcept : ledger_(ledger) {
  static const sigset_t blocked = asynchronous_signals();
  pthread_sigmask(SIG_BLOCK, &blocked, &saved_mask_);
  int idle = kIdle;
  open_ = ledger_.state_.compare_exchange_strong(idle, kSending, std::memory_order_acquire);
}

WireLedger::Send::~Send() {
  if (open_) {
    // Not a plain store: a claim that stopped waiting keeps the link.
    int sending = kSending;
    ledger_.state_.compare_exchange_strong(sending, kIdle, std::memory_order_release);
  }
  pthread_sigmask(SIG_SETMASK, &saved_mask_, nullptr);
}

void WireLedger::Send::sent(const uint8_t* data, size_t n) noexcept {
  if (open_) ledger_.append(data, n);
}

WireLedger::Snapshot WireLedger::claim() noexcept {
  for (int waited_ms = 0;; ++waited_ms) {
    int idle = kIdle;
    if (state_.compare_exchange_strong(idle, kClaimed, std::memory_order_acq_rel) || idle == kClaimed) break;
    if (waited_ms == 100) {
      state_.store(kClaimed, std::memory_order_release);
      break;
    }
    const timespec ms{0, 1000000};
    nanosleep(&ms, nullptr);
  }
  Snapshot s;
  s.sent = sent_;
  std::memcpy(s.tail, tail_, kTail);
  return s;
}

void WireLedger::record(const uint8_t* data, size_t n) noexcept { append(data, n); }

void WireLedger::append(const uint8_t* data, size_t n) noexcept {
  sent_ += n;
  if (n >= kTail) {
    std::memcpy(tail_, data + n - kTail, kTail);
    return;
  }
  std::memmove(tail_, tail_ + n, kTail - n);
  std::memcpy(tail_ + kTail - n, data, n);
}

}  // namespace bodyscan::hw::usb
