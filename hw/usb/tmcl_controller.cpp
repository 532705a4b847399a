#include "hw/usb/tmcl_controller.hpp"

#include <cmath>
#include <tuple>

#include "hw/safety.hpp"
#include "hw/usb/serial_link.hpp"
#include "hw/usb/usb_link.hpp"

namespace bodyscan::hw::usb {

using namespace tmcl;  // NOLINT(google-build-using-namespace): the protocol's names

std::vector<Request> TmclController::watchdog_program(uint8_t address, const std::vector<int>& laser_outputs,
                                                      int period_ms) {
  // 0      WAIT ticks(period)
  // 1      GGP  heartbeat, bank 2      accumulator = heartbeat
  // 2      COMP 0
  // 3      JC   NE, alive
  // 4..    SIO  output, bank 2, 0      (every laser output)
  //        JA   0
  // alive: CALC LOAD 0                 accumulator = 0
  //        AGP  heartbeat, bank 2      heartbeat = 0
  //        JA   0
  const auto n = static_cast<int32_t>(laser_outputs.size());
  const int32_t alive = 5 + n;
  std::vector<Request> p;
  p.push_back({address, kWAIT, kWaitTicks, 0, std::max(1, period_ms / 10)});
  p.push_back({address, kGGP, kHeartbeatVariable, kBankUserVariables, 0});
  p.push_back({address, kCOMP, 0, 0, 0});
  p.push_back({address, kJC, kJcNotEqual, 0, alive});
  for (int o : laser_outputs) p.push_back({address, kSIO, static_cast<uint8_t>(o), kBankOutputs, 0});
  p.push_back({address, kJA, 0, 0, 0});
  p.push_back({address, kCALC, kCalcLoad, 0, 0});
  p.push_back({address, kAGP, kHeartbeatVariable, kBankUserVariables, 0});
  p.push_back({address, kJA, 0, 0, 0});
  return p;
}

TmclController::TmclController(const RigDescription& rig, std::unique_ptr<ByteLink> link)
    : lasers_(rig.lasers),
      wiring_(rig.controller),
      link_(std::move(link)),
      client_(*link_, static_cast<uint8_t>(rig.controller.module_address),
              std::chrono::milliseconds(rig.controller.reply_timeout_ms)),
      laser_on_(rig.lasers.size()),
      homed_(rig.lasers.size(), false) {
  emergency_bytes_.assign(std::tuple_size_v<Frame>, 0);
  for (const auto& w : wiring_.lasers) {
    const Frame f = encode(
        Request{static_cast<uint8_t>(wiring_.module_address), kSIO, static_cast<uint8_t>(w.output), kBankOutputs, 0});
    emergency_bytes_.insert(emergency_bytes_.end(), f.begin(), f.end());
  }
}

StatusOr<std::unique_ptr<TmclController>> TmclController::open(const RigDescription& rig) {
  if (rig.controller.backend != "tmcl") return invalid_argument("the rig's controller is not a TMCL board");
  std::unique_ptr<ByteLink> link;
  if (!rig.controller.port.empty()) {
    ASSIGN_OR_RETURN(link, SerialLink::open(rig.controller.port));
  } else {
    ASSIGN_OR_RETURN(link,
                     UsbLink::open(rig.controller.usb_vendor, rig.controller.usb_product, rig.controller.usb_serial));
  }
  return open(rig, std::move(link));
}

StatusOr<std::unique_ptr<TmclController>> TmclController::open(const RigDescription& rig,
                                                               std::unique_ptr<ByteLink> link) {
  if (rig.controller.lasers.size() != rig.lasers.size())
    return invalid_argument("the controller's wiring does not match the lasers");
  std::unique_ptr<TmclController> c(new TmclController(rig, std::move(link)));
  RETURN_IF_ERROR(c->start());
  return c;
}

Status TmclController::start() {
  // The signal path first: from here on a crash switches the lasers off.
  emergency_slot_ = register_emergency_stop(&TmclController::emergency_stop, this);
  {
    std::lock_guard lock(mutex_);
    auto version = client_.firmware_version();
    if (!version.ok()) {
      return Status(version.status().code(), "the TMCL controller does not answer: " + version.status().message());
    }
    firmware_ = *version;
  }
  RETURN_IF_ERROR(all_lasers_off());
  if (wiring_.watchdog_ms > 0) {
    std::vector<int> outputs;
    for (const auto& w : wiring_.lasers) outputs.push_back(w.output);
    std::lock_guard lock(mutex_);
    RETURN_IF_ERROR(client_.call(kStopApplication, 0, 0, 0).status());
    RETURN_IF_ERROR(client_.call(kSGP, kHeartbeatVariable, kBankUserVariables, 1).status());
    RETURN_IF_ERROR(client_.call(kStartDownload, 0, 0, 0).status());
    for (const Request& r : watchdog_program(client_.address(), outputs, wiring_.watchdog_ms)) {
      Status st = client_.store(r.command, r.type, r.bank, r.value);
      if (!st.ok()) {
        (void)client_.call(kQuitDownload, 0, 0, 0);
        return Status(st.code(), "storing the laser watchdog in the controller: " + st.message());
      }
    }
    RETURN_IF_ERROR(client_.call(kQuitDownload, 0, 0, 0).status());
    RETURN_IF_ERROR(client_.call(kRunApplication, 0, 0, 0).status());
    feeder_ = std::thread([this] { feed_loop(); });
  }
  return Status::Ok();
}

TmclController::~TmclController() {
  if (feeder_.joinable()) {
    {
      std::lock_guard lock(feed_mutex_);
      stop_feeding_ = true;
    }
    feed_cv_.notify_all();
    feeder_.join();
  }
  (void)all_lasers_off();
  unregister_emergency_stop(emergency_slot_);
  // The watchdog program keeps running in the board: with no heartbeat any more it
  // holds the lasers off until the next open() replaces it.
}

void TmclController::feed_loop() {
  ensure_alternate_signal_stack();
  const auto period = std::chrono::milliseconds(std::max(20, wiring_.watchdog_ms / 4));
  std::unique_lock lock(feed_mutex_);
  while (!stop_feeding_) {
    lock.unlock();
    {
      std::lock_guard link_lock(mutex_);
      (void)client_.call(kSGP, kHeartbeatVariable, kBankUserVariables, 1);
    }
    lock.lock();
    feed_cv_.wait_for(lock, period, [this] { return stop_feeding_.load(); });
  }
}

void TmclController::emergency_stop(void* self) noexcept {
  // The board cuts the byte stream into 9-byte frames. A frame the normal path left
  // half sent (a signal between two write(2)s, a write that timed out) would take
  // the first bytes of the off frames as its tail, and every off frame after it
  // would be read out of step. So that frame is completed first, with a checksum
  // that cannot match: the board answers "wrong checksum" and runs nothing, and the
  // off frames start on a frame boundary.
  auto* c = static_cast<TmclController*>(self);
  constexpr size_t kFrameSize = std::tuple_size_v<Frame>;
  const WireLedger::Snapshot wire = c->link_->emergency_claim();
  const auto have = static_cast<size_t>(wire.sent % kFrameSize);
  uint8_t* out = c->emergency_bytes_.data() + kFrameSize;
  size_t size = c->emergency_bytes_.size() - kFrameSize;
  if (have > 0) {
    const size_t missing = kFrameSize - have;
    out -= missing;
    size += missing;
    unsigned sum = 0;  // of the frame's first eight bytes: those sent, then zeros
    for (size_t i = WireLedger::kTail - have; i < WireLedger::kTail; ++i) sum += wire.tail[i];
    for (size_t i = 0; i + 1 < missing; ++i) out[i] = 0;
    out[missing - 1] = static_cast<uint8_t>(sum + 1);
  }
  c->link_->emergency_write(out, size);
}

Status TmclController::check_laser(int i) const {
  if (i < 0 || i >= num_lasers()) {
    return invalid_argument("no laser or motor " + std::to_string(i) + " (the rig has " + std::to_string(num_lasers()) +
                            ")");
  }
  return Status::Ok();
}

Status TmclController::output(int port, bool on) {
  if (port < 0) return Status::Ok();  // not wired
  return client_.call(kSIO, static_cast<uint8_t>(port), kBankOutputs, on ? 1 : 0).status();
}

Status TmclController::set_room_lights(bool on) {
  std::lock_guard lock(mutex_);
  return output(wiring_.room_lights_output, on);
}

Status TmclController::set_frame_light_circuits(bool front_poles, bool back_poles) {
  std::lock_guard lock(mutex_);
  RETURN_IF_ERROR(output(wiring_.front_lights_output, front_poles));
  return output(wiring_.back_lights_output, back_poles);
}

Status TmclController::set_laser(int laser, bool on) {
  RETURN_IF_ERROR(check_laser(laser));
  // A crash on this thread while the laser is on must still reach the handlers,
  // stack overflow included (hw/safety.hpp).
  if (on) ensure_alternate_signal_stack();
  Status st;
  {
    std::lock_guard lock(mutex_);
    st = output(wiring_.lasers[static_cast<size_t>(laser)].output, on);
  }
  if (st.ok()) {
    laser_on_[static_cast<size_t>(laser)] = on;
    return st;
  }
  (void)all_lasers_off();
  return Status(st.code(), "laser '" + lasers_[static_cast<size_t>(laser)].id + "': " + st.message());
}

Status TmclController::all_lasers_off() {
  Status first;
  std::lock_guard lock(mutex_);
  for (size_t i = 0; i < wiring_.lasers.size(); ++i) {
    Status st = output(wiring_.lasers[i].output, false);
    if (st.ok())
      laser_on_[i] = false;
    else if (first.ok())
      first = Status(st.code(), "switching laser '" + lasers_[i].id + "' off: " + st.message());
  }
  return first;
}

bool TmclController::laser_on(int laser) const {
  return laser >= 0 && laser < num_lasers() && laser_on_[static_cast<size_t>(laser)].load();
}

Status TmclController::call_or_lasers_off(uint8_t command, uint8_t type, uint8_t bank, int32_t value, int32_t* result) {
  StatusOr<int32_t> r = [&] {
    std::lock_guard lock(mutex_);
    return client_.call(command, type, bank, value);
  }();
  if (!r.ok()) {
    (void)all_lasers_off();
    return r.status();
  }
  if (result) *result = *r;
  return Status::Ok();
}

Status TmclController::home(int motor) {
  RETURN_IF_ERROR(check_laser(motor));
  const auto& w = wiring_.lasers[static_cast<size_t>(motor)];
  const std::string who = "the motor of laser '" + lasers_[static_cast<size_t>(motor)].id + "'";
  const auto axis = static_cast<uint8_t>(w.axis);
  RETURN_IF_ERROR(call_or_lasers_off(kRFS, kRfsStart, axis, 0, nullptr).with_context(who));
  RETURN_IF_ERROR(wait_for_axis(axis, kRFS, kRfsStatus, /*not busy*/ 0, kRFS, kRfsStop, wiring_.home_timeout_ms,
                                std::chrono::milliseconds(10), who,
                                "did not find its reference switch within " + std::to_string(wiring_.home_timeout_ms) +
                                    " ms: check the switch and its wiring"));
  homed_[static_cast<size_t>(motor)] = true;
  return move_to(motor, 0);
}

Status TmclController::move_to(int motor, int step) {
  RETURN_IF_ERROR(check_laser(motor));
  const LaserDescription& l = lasers_[static_cast<size_t>(motor)];
  if (!homed_[static_cast<size_t>(motor)])
    return failed_precondition("motor of laser '" + l.id + "' is not homed: call home() first");
  if (step < l.min_step || step > l.max_step) {
    return out_of_range("laser '" + l.id + "': step " + std::to_string(step) + " is outside its sweep [" +
                        std::to_string(l.min_step) + ", " + std::to_string(l.max_step) + "]");
  }
  const auto& w = wiring_.lasers[static_cast<size_t>(motor)];
  const auto axis = static_cast<uint8_t>(w.axis);
  const std::string who = "the motor of laser '" + l.id + "'";
  const int32_t target = w.home_offset + step * w.microsteps_per_step;
  RETURN_IF_ERROR(call_or_lasers_off(kMVP, kMvpAbsolute, axis, target, nullptr).with_context(who));
  return wait_for_axis(axis, kGAP, kApPositionReached, /*reached*/ 1, kMST, 0, wiring_.move_timeout_ms,
                       std::chrono::milliseconds(1), who,
                       "did not reach step " + std::to_string(step) + " within " +
                           std::to_string(wiring_.move_timeout_ms) + " ms: is it stalled?");
}

Status TmclController::wait_for_axis(uint8_t axis, uint8_t command, uint8_t type, int32_t done_when,
                                     uint8_t stop_command, uint8_t stop_type, int timeout_ms,
                                     std::chrono::milliseconds every, const std::string& who, const std::string& late) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  for (;;) {
    int32_t answer = 0;
    RETURN_IF_ERROR(call_or_lasers_off(command, type, axis, 0, &answer).with_context(who));
    if (answer == done_when) return Status::Ok();
    if (std::chrono::steady_clock::now() > deadline) {
      (void)call_or_lasers_off(stop_command, stop_type, axis, 0, nullptr);
      (void)all_lasers_off();
      return deadline_exceeded(who + " " + late);
    }
    std::this_thread::sleep_for(every);
  }
}

StatusOr<int> TmclController::current_step(int motor) const {
  RETURN_IF_ERROR(check_laser(motor));
  if (!homed_[static_cast<size_t>(motor)])
    return failed_precondition("motor " + std::to_string(motor) + " is not homed");
  const auto& w = wiring_.lasers[static_cast<size_t>(motor)];
  StatusOr<int32_t> pos = [&] {
    std::lock_guard lock(mutex_);
    return client_.call(kGAP, kApActualPosition, static_cast<uint8_t>(w.axis), 0);
  }();
  if (!pos.ok()) return pos.status();
  return static_cast<int>(std::lround(static_cast<double>(*pos - w.home_offset) / w.microsteps_per_step));
}

}  // namespace bodyscan::hw::usb
