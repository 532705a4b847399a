// A byte pipe to a controller board: a serial port (a USB CDC-ACM device node, a
// pseudo-terminal in tests), a USB device through libusb, or an in-process
// simulated board. Protocols (hw/usb/tmcl.hpp) talk to this and nothing else.
#pragma once

#include <signal.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/status.hpp"

namespace bodyscan::hw::usb {

// The bytes a link has put on the wire since it opened, kept for the signal path:
// a protocol of fixed-size frames learns from it where the board's parser stands
// (sent % frame size) and the bytes of a frame the normal path left half sent, and
// completes that frame before its emergency frames (tmcl_controller.cpp).
//
// The normal path holds a Send across each system call that may put bytes on the
// wire and reports what went. The signal path claims the ledger for good: once
// claim() returns, no Send is in flight and none opens again (the link's writes
// fail; the process is ending), so the count it returns is exact. A Send blocks
// the asynchronous signals on its thread for the length of the call, so that the
// thread's own handler never runs between bytes leaving and their being counted.
class WireLedger {
 public:
  static constexpr size_t kTail = 16;
  struct Snapshot {
    uint64_t sent = 0;
    // The last min(sent, kTail) bytes sent, ending at tail[kTail - 1].
    uint8_t tail[kTail] = {};
  };

  class Send {
   public:
    explicit Send(WireLedger& ledger) noexcept;
    ~Send();
    Send(const Send&) = delete;
    Send& operator=(const Send&) = delete;
    // False when the signal path has claimed the link: write nothing.
    bool open() const { return open_; }
    void sent(const uint8_t* data, size_t n) noexcept;

   private:
    WireLedger& ledger_;
    sigset_t saved_mask_;
    bool open_ = false;
  };

  // Signal path; async-signal-safe. Waits up to 100 ms for a Send in flight on
  // another thread; past that it claims anyway and the count is best effort.
  // Claiming again returns the count as it stands.
  Snapshot claim() noexcept;
  // The signal path's own bytes, after claim().
  void record(const uint8_t* data, size_t n) noexcept;

 private:
  enum : int { kIdle, kSending, kClaimed };
  void append(const uint8_t* data, size_t n) noexcept;
  std::atomic<int> state_{kIdle};
  uint64_t sent_ = 0;  // written by whoever holds state_ (a Send, or the claimer)
  uint8_t tail_[kTail] = {};
};

class ByteLink {
 public:
  virtual ~ByteLink() = default;

  // Writes all of `data` or fails: unavailable when the device is gone,
  // deadline_exceeded when it stops taking bytes.
  virtual Status write(const uint8_t* data, size_t size, std::chrono::milliseconds timeout) = 0;
  // Reads exactly `size` bytes. deadline_exceeded when they do not all arrive within
  // `timeout` (the board is silent); unavailable when the device is gone.
  virtual Status read(uint8_t* data, size_t size, std::chrono::milliseconds timeout) = 0;
  // Drops whatever has arrived and not been read (after a garbled reply).
  virtual void discard_input() = 0;

  // The signal path's hold on the link (WireLedger::claim): from its return normal
  // writes fail with unavailable, and it says what went on the wire before.
  WireLedger::Snapshot emergency_claim() noexcept { return ledger_.claim(); }
  // Writes `data` from a signal handler, after emergency_claim(): only
  // async-signal-safe system calls, no allocation, no locks, best effort. The crash
  // path of laser safety uses it.
  virtual bool emergency_write(const uint8_t* data, size_t size) noexcept = 0;

  // For messages: "/dev/ttyACM0", "USB 2a3c:0100 on bus 1 device 7".
  virtual const std::string& name() const = 0;

 protected:
  // Every byte the link puts on the wire goes through it.
  WireLedger ledger_;
};

}  // namespace bodyscan::hw::usb
