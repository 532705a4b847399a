#include "hw/device_rig.hpp"

#include "hw/aravis/aravis_camera.hpp"
#include "hw/usb/tmcl_controller.hpp"

namespace bodyscan::hw {

// A real controller whose every switch and move is also made on the simulation's
// controller, so that simulated cameras render what the real board does.
class DeviceRig::Mirror : public Controller {
 public:
  Mirror(Controller& real, Controller& sim) : real_(real), sim_(sim) {}
  int num_lasers() const override { return real_.num_lasers(); }
  Status set_room_lights(bool on) override { return both(&Controller::set_room_lights, on); }
  Status set_frame_light_circuits(bool f, bool b) override { return both(&Controller::set_frame_light_circuits, f, b); }
  Status set_laser(int laser, bool on) override {
    Status st = real_.set_laser(laser, on);
    (void)sim_.set_laser(laser, st.ok() && on);
    return st;
  }
  Status all_lasers_off() override {
    (void)sim_.all_lasers_off();
    return real_.all_lasers_off();
  }
  bool laser_on(int laser) const override { return real_.laser_on(laser); }
  Status home(int motor) override { return both(&Controller::home, motor); }
  Status move_to(int motor, int step) override { return both(&Controller::move_to, motor, step); }
  StatusOr<int> current_step(int motor) const override { return real_.current_step(motor); }

 private:
  // The real board first; the simulation follows only what the board did.
  template <class... Params, class... Args>
  Status both(Status (Controller::*f)(Params...), Args... args) {
    RETURN_IF_ERROR((real_.*f)(args...));
    return (sim_.*f)(args...);
  }
  Controller& real_;
  Controller& sim_;
};

StatusOr<std::unique_ptr<DeviceRig>> DeviceRig::open(const RigDescription& rig, const TriangleMesh* subject) {
  std::unique_ptr<DeviceRig> r(new DeviceRig());
  r->rig_ = rig;
  bool any_sim = rig.controller.backend == "sim";
  for (const CameraDescription& c : rig.cameras) any_sim = any_sim || c.device.backend == "sim";
  if (any_sim) {
    if (subject) {
      ASSIGN_OR_RETURN(r->sim_, sim::SimulatedRig::create(rig, *subject));
    } else {
      ASSIGN_OR_RETURN(r->sim_, sim::SimulatedRig::create(rig));
    }
  }
  // The controller first: whatever fails after it, its destructor leaves the lasers off.
  if (rig.controller.backend == "tmcl") {
    ASSIGN_OR_RETURN(auto board, usb::TmclController::open(rig));
    r->real_controller_ = std::move(board);
    if (r->sim_) {
      r->mirror_ = std::make_unique<Mirror>(*r->real_controller_, r->sim_->controller());
      r->controller_ = r->mirror_.get();
    } else {
      r->controller_ = r->real_controller_.get();
    }
  } else {
    r->controller_ = &r->sim_->controller();
  }
  for (size_t i = 0; i < rig.cameras.size(); ++i) {
    const CameraDescription& c = rig.cameras[i];
    if (c.device.backend == "aravis") {
      ASSIGN_OR_RETURN(auto cam, aravis::AravisCamera::open(c));
      r->cameras_.push_back(cam.get());
      r->owned_cameras_.push_back(std::move(cam));
    } else {
      r->cameras_.push_back(&r->sim_->camera(i));
    }
  }
  return r;
}

DeviceRig::~DeviceRig() {
  if (controller_) (void)controller_->all_lasers_off();
}

Status DeviceRig::hold_dot_grid(size_t camera, bool held) {
  if (camera >= cameras_.size()) return invalid_argument("no camera " + std::to_string(camera));
  if (camera_simulated(camera)) {
    sim_->hold_dot_grid(camera, held);
    return Status::Ok();
  }
  if (!held) return Status::Ok();
  return failed_precondition(
      "camera '" + rig_.cameras[camera].id +
      "' is real: hold the dot-grid board before it by hand (docs/hardware.md, \"Lens calibration\")");
}

}  // namespace bodyscan::hw
