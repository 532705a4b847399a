// The controller interface: room lights, frame lights, lasers and their stepper
// motors (thesis §2.4). Backends: the simulated rig (hw/sim) and a USB stepper and
// relay board (a later backend).
//
// Laser safety: line lasers point at people. all_lasers_off() must switch every
// laser off whatever state the controller is in, and LasersOff guarantees it on
// every path out of a scope, exceptions included.
#pragma once

#include "core/status.hpp"

namespace bodyscan::hw {

class Controller {
 public:
  virtual ~Controller() = default;
  virtual int num_lasers() const = 0;  // lasers and their motors share an index

  virtual Status set_room_lights(bool on) = 0;
  // The frame lights are wired in two circuits: the front poles' lights (both
  // frames, both faces) and the back poles'. Switching one alone tells a camera
  // which side of the frame it faces (thesis §3.1.2 asked for manual entry there).
  virtual Status set_frame_light_circuits(bool front_poles, bool back_poles) = 0;
  Status set_frame_lights(bool on) { return set_frame_light_circuits(on, on); }
  virtual Status set_laser(int laser, bool on) = 0;
  // Tries every laser even if one fails; returns the first error.
  virtual Status all_lasers_off() = 0;
  virtual bool laser_on(int laser) const = 0;

  // Stepper motors: home() drives to the reference switch and calls that step 0;
  // move_to() blocks until the motor stands at `step`.
  virtual Status home(int motor) = 0;
  virtual Status move_to(int motor, int step) = 0;
  virtual StatusOr<int> current_step(int motor) const = 0;
};

// Switches every laser off when the scope ends, however it ends.
class LasersOff {
 public:
  explicit LasersOff(Controller& c) : c_(c) {}
  ~LasersOff() { (void)c_.all_lasers_off(); }
  LasersOff(const LasersOff&) = delete;
  LasersOff& operator=(const LasersOff&) = delete;

 private:
  Controller& c_;
};

}  // namespace bodyscan::hw
