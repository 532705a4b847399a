// A byte pipe to a controller board: a serial port (a USB CDC-ACM device node, a
// pseudo-terminal in tests), a USB device through libusb, or an in-process
// simulated board. Protocols (hw/usb/tmcl.hpp) talk to this and nothing else.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>

#include "recon/core/status.hpp"

namespace bodyscan::hw::usb {

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

  // Writes `data` from a signal handler: only async-signal-safe system calls, no
  // allocation, no locks, best effort. The crash path of laser safety uses it.
  virtual bool emergency_write(const uint8_t* data, size_t size) noexcept = 0;

  // For messages: "/dev/ttyACM0", "USB 2a3c:0100 on bus 1 device 7".
  virtual const std::string& name() const = 0;
};

}  // namespace bodyscan::hw::usb
