// TMCL, the Trinamic Motion Control Language: the documented binary command
// protocol of Trinamic (now Analog Devices) stepper controller modules - the
// TMCM-6110 (6 axes, 8 digital outputs) and TMCM-3110 (3 axes) among them - over
// their USB virtual serial port, RS-485 or CAN. docs/hardware.md says why this
// board family replaces the thesis's SimStep boards.
//
// Every request and reply is 9 bytes:
//   request: module address, command, type, motor/bank, value (int32, big-endian), checksum
//   reply:   host address, module address, status, command, value, checksum
// where the checksum is the sum of the first eight bytes, modulo 256. Status 100 is
// success; 101 "loaded" answers a command sent in download mode; 1-6 are errors.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

#include "hw/usb/byte_link.hpp"

namespace bodyscan::hw::usb::tmcl {

// Command numbers (TMCL reference).
enum Command : uint8_t {
  kROR = 1,
  kROL = 2,
  kMST = 3,
  kMVP = 4,
  kSAP = 5,
  kGAP = 6,
  kSTAP = 7,
  kRSAP = 8,
  kSGP = 9,
  kGGP = 10,
  kRFS = 13,
  kSIO = 14,
  kGIO = 15,
  kCALC = 19,
  kCOMP = 20,
  kJC = 21,
  kJA = 22,
  kWAIT = 27,
  kSTOP = 28,
  kAAP = 34,
  kAGP = 35,
  kStopApplication = 128,
  kRunApplication = 129,
  kResetApplication = 131,
  kStartDownload = 132,
  kQuitDownload = 133,
  kGetApplicationStatus = 135,
  kGetFirmwareVersion = 136,
};

// Types of the commands above that take one.
enum : uint8_t {
  kMvpAbsolute = 0,
  kMvpRelative = 1,
  kRfsStart = 0,
  kRfsStop = 1,
  kRfsStatus = 2,
  kWaitTicks = 0,   // WAIT: value in 10 ms ticks
  kCalcLoad = 9,    // CALC: accumulator = value
  kJcNotEqual = 3,  // JC: jump if the last COMP found them unequal
};
// Banks for SIO/GIO and SGP/GGP.
enum : uint8_t { kBankInputs = 0, kBankAnalog = 1, kBankOutputs = 2, kBankUserVariables = 2 };
// Axis parameters.
enum : uint8_t {
  kApTargetPosition = 0,
  kApActualPosition = 1,
  kApMaxVelocity = 4,
  kApMaxAcceleration = 5,
  kApPositionReached = 8,
  kApReferenceSwitch = 9
};

enum ReplyStatus : uint8_t {
  kSuccess = 100,
  kLoaded = 101,
  kWrongChecksum = 1,
  kInvalidCommand = 2,
  kWrongType = 3,
  kInvalidValue = 4,
  kEepromLocked = 5,
  kNotAvailable = 6,
};
const char* status_text(uint8_t status);

using Frame = std::array<uint8_t, 9>;

struct Request {
  uint8_t address = 1, command = 0, type = 0, bank = 0;
  int32_t value = 0;
};
struct Reply {
  uint8_t host = 2, address = 1, status = kSuccess, command = 0;
  int32_t value = 0;
};

uint8_t checksum(const uint8_t* bytes);  // of the first eight
Frame encode(const Request& r);
Frame encode(const Reply& r);
bool checksum_ok(const Frame& f);
Request decode_request(const Frame& f);
Reply decode_reply(const Frame& f);

// One module on a link. Requests are answered in order; a garbled or missing reply
// is retried (every request this project sends is idempotent), then reported.
class Client {
 public:
  Client(ByteLink& link, uint8_t module_address = 1, std::chrono::milliseconds timeout = std::chrono::milliseconds(250),
         int attempts = 3)
      : link_(link), address_(module_address), timeout_(timeout), attempts_(attempts) {}

  // Sends a request and returns the reply's value. Errors: deadline_exceeded or
  // unavailable from the link (after the retries), internal for a reply that never
  // checks out, invalid_argument (with the board's words) for an error status.
  StatusOr<int32_t> call(uint8_t command, uint8_t type, uint8_t bank, int32_t value);
  // Download mode: the board stores the command instead of running it (status 101).
  Status store(uint8_t command, uint8_t type, uint8_t bank, int32_t value);
  // The module's firmware version string, e.g. "6110V130".
  StatusOr<std::string> firmware_version();

  ByteLink& link() { return link_; }
  uint8_t address() const { return address_; }

 private:
  StatusOr<Reply> exchange(const Request& r);
  // Writes `out` and reads the 9-byte answer, retrying (input discarded) on a
  // link timeout or an answer `check` rejects; unavailable at once.
  StatusOr<Frame> transact(const Frame& out, const std::function<Status(const Frame&)>& check);
  ByteLink& link_;
  uint8_t address_;
  std::chrono::milliseconds timeout_;
  int attempts_;
};

}  // namespace bodyscan::hw::usb::tmcl
