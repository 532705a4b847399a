// The rig's devices, opened from its description: each camera simulated or a
// GenICam camera through Aravis, the controller simulated or a TMCL board. A
// description may mix them (real cameras before the board arrives; a real board
// with simulated cameras to bring up the wiring): with a real controller, the
// simulated cameras see what the real board switches.
#pragma once

#include <memory>
#include <vector>

#include "hw/camera.hpp"
#include "hw/controller.hpp"
#include "hw/rig_description.hpp"
#include "hw/sim/sim_rig.hpp"

namespace bodyscan::hw {

class DeviceRig {
 public:
  // `subject` replaces the description's simulated subject when given.
  static StatusOr<std::unique_ptr<DeviceRig>> open(const RigDescription& rig, const TriangleMesh* subject = nullptr);
  ~DeviceRig();

  const RigDescription& description() const { return rig_; }
  Controller& controller() { return *controller_; }
  size_t num_cameras() const { return cameras_.size(); }
  Camera& camera(size_t i) { return *cameras_.at(i); }
  bool camera_simulated(size_t i) const { return rig_.cameras.at(i).device.backend == "sim"; }
  // The simulation behind the simulated devices; null when every device is real.
  sim::SimulatedRig* simulation() { return sim_.get(); }

  // The lens dot grid before camera i: the simulation holds it for a simulated
  // camera; a real camera needs a person (failed_precondition here, with what to do).
  Status hold_dot_grid(size_t camera, bool held);

 private:
  DeviceRig() = default;
  class Mirror;
  RigDescription rig_;
  std::unique_ptr<sim::SimulatedRig> sim_;
  std::unique_ptr<Controller> real_controller_;
  std::unique_ptr<Controller> mirror_;
  Controller* controller_ = nullptr;
  std::vector<std::unique_ptr<Camera>> owned_cameras_;
  std::vector<Camera*> cameras_;
};

}  // namespace bodyscan::hw
