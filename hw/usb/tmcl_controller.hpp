// The rig's controller on a TMCL stepper module (a TMCM-6110: six axes and eight
// digital outputs on one board, as the thesis's routed SimStep boards gave it):
// lasers and lights on digital outputs, the lasers' motors on axes, wired as the
// rig description's "controller" section says.
//
// Laser safety, on top of Controller's contract:
// - every laser output is switched off when the controller opens and closes, and
//   on any error the board reports;
// - an emergency stop (hw/safety.hpp) is registered for the crash and signal
//   paths: the prepared SIO frames written straight to the link, after completing
//   (with a checksum the board refuses) any frame the normal path left half sent;
// - a board-side watchdog: a short TMCL program stored in the module and run by it
//   switches every laser output off when the host has not fed it for
//   `watchdog_ms` (killed process, hung machine, cable pulled while the board keeps
//   its power). A feeder thread writes the heartbeat while the controller is open.
#pragma once

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "hw/controller.hpp"
#include "hw/rig_description.hpp"
#include "hw/usb/byte_link.hpp"
#include "hw/usb/tmcl.hpp"

namespace bodyscan::hw::usb {

class TmclController : public Controller {
 public:
  // Opens the board the description names (its serial port, or USB through
  // libusb), checks it answers, switches every laser off and starts the watchdog.
  static StatusOr<std::unique_ptr<TmclController>> open(const RigDescription& rig);
  // On a link already open (tests: a simulated board in process or on a pty).
  static StatusOr<std::unique_ptr<TmclController>> open(const RigDescription& rig, std::unique_ptr<ByteLink> link);
  ~TmclController() override;

  int num_lasers() const override { return static_cast<int>(wiring_.lasers.size()); }
  Status set_room_lights(bool on) override;
  Status set_frame_light_circuits(bool front_poles, bool back_poles) override;
  Status set_laser(int laser, bool on) override;
  Status all_lasers_off() override;
  bool laser_on(int laser) const override;
  Status home(int motor) override;
  Status move_to(int motor, int step) override;
  StatusOr<int> current_step(int motor) const override;

  const std::string& firmware() const { return firmware_; }
  const std::string& link_name() const { return link_->name(); }

  // The user variable the watchdog program reads (bank 2), and the program itself:
  // what open() stores in the module. Public for tests and docs/hardware.md.
  static constexpr uint8_t kHeartbeatVariable = 55;
  static std::vector<tmcl::Request> watchdog_program(uint8_t address, const std::vector<int>& laser_outputs,
                                                     int period_ms);

 private:
  TmclController(const RigDescription& rig, std::unique_ptr<ByteLink> link);
  Status start();
  Status check_laser(int i) const;
  Status output(int port, bool on);  // under mutex_
  Status call_or_lasers_off(uint8_t command, uint8_t type, uint8_t bank, int32_t value, int32_t* result);
  // Asks (command, type) of `axis` every `every` until the answer is `done_when`;
  // past `timeout_ms` it sends `stop_command` (with `stop_type`), switches the
  // lasers off and returns deadline_exceeded(who + " " + late).
  Status wait_for_axis(uint8_t axis, uint8_t command, uint8_t type, int32_t done_when, uint8_t stop_command,
                       uint8_t stop_type, int timeout_ms, std::chrono::milliseconds every, const std::string& who,
                       const std::string& late);
  void feed_loop();
  static void emergency_stop(void* self) noexcept;

  std::vector<LaserDescription> lasers_;
  ControllerDescription wiring_;
  std::unique_ptr<ByteLink> link_;
  mutable std::mutex mutex_;  // one request at a time on the link
  mutable tmcl::Client client_;
  // For the signal path: room for the tail of a half-sent frame, then the SIO off
  // frames of every laser output.
  std::vector<uint8_t> emergency_bytes_;
  std::vector<std::atomic<bool>> laser_on_;
  std::vector<bool> homed_;
  std::string firmware_;
  int emergency_slot_ = -1;
  std::atomic<bool> stop_feeding_{false};
  std::mutex feed_mutex_;
  std::condition_variable feed_cv_;
  std::thread feeder_;
};

}  // namespace bodyscan::hw::usb
