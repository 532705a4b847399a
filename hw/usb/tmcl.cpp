#include "hw/usb/tmcl.hpp"

namespace bodyscan::hw::usb::tmcl {

const char* status_text(uint8_t status) {
  switch (status) {
    case kSuccess: return "success";
    case kLoaded: return "command loaded";
    case kWrongChecksum: return "wrong checksum";
    case kInvalidCommand: return "invalid command";
    case kWrongType: return "wrong type";
    case kInvalidValue: return "invalid value";
    case kEepromLocked: return "configuration EEPROM locked";
    case kNotAvailable: return "command not available";
    default: return "unknown status";
  }
}

uint8_t checksum(const uint8_t* b) {
  unsigned sum = 0;
  for (int i = 0; i < 8; ++i) sum += b[i];
  return static_cast<uint8_t>(sum & 0xff);
}

namespace {
Frame pack(uint8_t a, uint8_t b, uint8_t c, uint8_t d, int32_t value) {
  const auto v = static_cast<uint32_t>(value);
  Frame f{a,
          b,
          c,
          d,
          static_cast<uint8_t>(v >> 24),
          static_cast<uint8_t>(v >> 16),
          static_cast<uint8_t>(v >> 8),
          static_cast<uint8_t>(v),
          0};
  f[8] = checksum(f.data());
  return f;
}
int32_t value_of(const Frame& f) {
  return static_cast<int32_t>((uint32_t{f[4]} << 24) | (uint32_t{f[5]} << 16) | (uint32_t{f[6]} << 8) | f[7]);
}
}  // namespace

Frame encode(const Request& r) { return pack(r.address, r.command, r.type, r.bank, r.value); }
Frame encode(const Reply& r) { return pack(r.host, r.address, r.status, r.command, r.value); }
bool checksum_ok(const Frame& f) { return checksum(f.data()) == f[8]; }
Request decode_request(const Frame& f) { return {f[0], f[1], f[2], f[3], value_of(f)}; }
Reply decode_reply(const Frame& f) { return {f[0], f[1], f[2], f[3], value_of(f)}; }

StatusOr<Frame> Client::transact(const Frame& out, const std::function<Status(const Frame&)>& check) {
  Status last;
  for (int attempt = 0; attempt < attempts_; ++attempt) {
    if (attempt > 0) link_.discard_input();
    Status st = link_.write(out.data(), out.size(), timeout_);
    Frame in{};
    if (st.ok()) st = link_.read(in.data(), in.size(), timeout_);
    if (st.ok()) st = check(in);
    if (st.ok()) return in;
    if (st.code() == StatusCode::kUnavailable) return st;
    last = st;
  }
  return Status(last.code(), last.message() + " (" + std::to_string(attempts_) + " tries)");
}

StatusOr<Reply> Client::exchange(const Request& r) {
  ASSIGN_OR_RETURN(const Frame in, transact(encode(r), [&](const Frame& f) -> Status {
                     if (!checksum_ok(f))
                       return internal_error("the controller on " + link_.name() + " sent a reply with a bad checksum");
                     const Reply rep = decode_reply(f);
                     if (rep.address != address_ || rep.command != r.command) {
                       return internal_error("the controller on " + link_.name() +
                                             " answered another request (command " + std::to_string(rep.command) +
                                             " from module " + std::to_string(rep.address) + ")");
                     }
                     if (rep.status == kWrongChecksum) {  // our frame was damaged on the way
                       return internal_error("the controller on " + link_.name() + " received a damaged command");
                     }
                     return Status::Ok();
                   }));
  return decode_reply(in);
}

StatusOr<int32_t> Client::call(uint8_t command, uint8_t type, uint8_t bank, int32_t value) {
  ASSIGN_OR_RETURN(const Reply rep, exchange({address_, command, type, bank, value}));
  if (rep.status != kSuccess) {
    return invalid_argument("the controller on " + link_.name() + " refused command " + std::to_string(command) +
                            " (type " + std::to_string(type) + ", bank " + std::to_string(bank) + ", value " +
                            std::to_string(value) + "): " + status_text(rep.status));
  }
  return rep.value;
}

Status Client::store(uint8_t command, uint8_t type, uint8_t bank, int32_t value) {
  ASSIGN_OR_RETURN(const Reply rep, exchange({address_, command, type, bank, value}));
  if (rep.status != kLoaded && rep.status != kSuccess) {
    return invalid_argument("the controller on " + link_.name() + " did not store command " + std::to_string(command) +
                            ": " + status_text(rep.status));
  }
  return Status::Ok();
}

StatusOr<std::string> Client::firmware_version() {
  // Type 0 answers with the host address and then eight ASCII characters in place of
  // the rest of the reply (no checksum).
  ASSIGN_OR_RETURN(const Frame in,
                   transact(encode(Request{address_, kGetFirmwareVersion, 0, 0, 0}), [&](const Frame& f) -> Status {
                     for (size_t i = 1; i < 9; ++i)
                       if (f[i] < 0x20 || f[i] >= 0x7f)
                         return internal_error("the controller on " + link_.name() +
                                               " answered the version request with binary data");
                     return Status::Ok();
                   }));
  return std::string(reinterpret_cast<const char*>(in.data()) + 1, 8);
}

}  // namespace bodyscan::hw::usb::tmcl
