#include "hw/sim/sim_rig.hpp"

#include "hw/sim/pose_body.hpp"

#include <optional>

#include "recon/io/ply.hpp"

namespace bodyscan::hw::sim {

class SimulatedRig::SimController : public Controller {
 public:
  explicit SimController(const RigDescription& rig)
      : rig_(rig), laser_on_(rig.lasers.size(), false), step_(rig.lasers.size(), 0), homed_(rig.lasers.size(), false) {}
  int num_lasers() const override { return static_cast<int>(rig_.lasers.size()); }

  Status set_room_lights(bool on) override {
    room_ = on;
    return {};
  }
  Status set_frame_light_circuits(bool front_poles, bool back_poles) override {
    front_ = front_poles;
    back_ = back_poles;
    return {};
  }
  Status set_laser(int laser, bool on) override {
    RETURN_IF_ERROR(check(laser));
    laser_on_[static_cast<size_t>(laser)] = on;
    return {};
  }
  Status all_lasers_off() override {
    std::fill(laser_on_.begin(), laser_on_.end(), false);
    return {};
  }
  bool laser_on(int laser) const override {
    return laser >= 0 && laser < num_lasers() && laser_on_[static_cast<size_t>(laser)];
  }
  Status home(int motor) override {
    RETURN_IF_ERROR(check(motor));
    step_[static_cast<size_t>(motor)] = 0;
    homed_[static_cast<size_t>(motor)] = true;
    return {};
  }
  Status move_to(int motor, int step) override {
    RETURN_IF_ERROR(check(motor));
    const LaserDescription& l = rig_.lasers[static_cast<size_t>(motor)];
    if (!homed_[static_cast<size_t>(motor)]) {
      return failed_precondition("motor of laser '" + l.id + "' is not homed: call home() first");
    }
    if (step < l.min_step || step > l.max_step) {
      return out_of_range("laser '" + l.id + "': step " + std::to_string(step) + " is outside its sweep [" +
                          std::to_string(l.min_step) + ", " + std::to_string(l.max_step) + "]");
    }
    step_[static_cast<size_t>(motor)] = step;
    return {};
  }
  StatusOr<int> current_step(int motor) const override {
    RETURN_IF_ERROR(check(motor));
    if (!homed_[static_cast<size_t>(motor)])
      return failed_precondition("motor " + std::to_string(motor) + " is not homed");
    return step_[static_cast<size_t>(motor)];
  }

  bool room() const { return room_; }
  bool front_lights() const { return front_; }
  bool back_lights() const { return back_; }
  int step(size_t i) const { return step_[i]; }

 private:
  Status check(int i) const {
    if (i < 0 || i >= num_lasers()) {
      return invalid_argument("no laser or motor " + std::to_string(i) + " (the rig has " +
                              std::to_string(num_lasers()) + ")");
    }
    return {};
  }
  const RigDescription& rig_;
  bool room_ = false, front_ = false, back_ = false;
  std::vector<bool> laser_on_;
  std::vector<int> step_;
  std::vector<bool> homed_;
};

class SimulatedRig::SimCamera : public Camera {
 public:
  SimCamera(SimulatedRig& rig, size_t index) : rig_(rig), index_(index) {
    const CameraDescription& d = rig.rig_.cameras[index];
    info_.id = d.id;
    info_.vendor = "bodyscan";
    info_.model = "simulated";
    info_.serial = "sim-" + d.id;
    info_.width = d.width;
    info_.height = d.height;
    info_.formats = {PixelFormat::kMono8, PixelFormat::kMono12, PixelFormat::kMono16};
    exposure_.format = d.pixel_format;
    exposure_.exposure_us = d.exposure_us;
    exposure_.gain_db = d.gain_db;
  }
  const CameraInfo& info() const override { return info_; }
  Status set_pixel_format(PixelFormat f) override {
    exposure_.format = f;
    return {};
  }
  Status set_exposure_us(double e) override {
    if (!(e >= 10 && e <= 1e6)) return out_of_range("camera '" + info_.id + "': exposure must be 10..1000000 us");
    exposure_.exposure_us = e;
    return {};
  }
  Status set_gain_db(double g) override {
    if (!(g >= 0 && g <= 24)) return out_of_range("camera '" + info_.id + "': gain must be 0..24 dB");
    exposure_.gain_db = g;
    return {};
  }
  PixelFormat pixel_format() const override { return exposure_.format; }
  double exposure_us() const override { return exposure_.exposure_us; }
  double gain_db() const override { return exposure_.gain_db; }

  StatusOr<Frame> grab(std::chrono::milliseconds timeout) override {
    if (fail_after_ && answered_ >= *fail_after_) {
      if (fail_code_ == StatusCode::kUnavailable) return unavailable("camera '" + info_.id + "' is disconnected");
      return deadline_exceeded("camera '" + info_.id + "' sent no frame within " + std::to_string(timeout.count()) +
                               " ms");
    }
    ++answered_;
    const uint64_t id = ++frame_id_;
    const double time = static_cast<double>(id - 1) / rig_.rig_.simulation.frame_rate_hz;
    Frame f;
    if (rig_.dot_grid_held_[index_]) {
      CameraDescription d = rig_.rig_.cameras[index_];
      d.pixel_format = exposure_.format;
      d.exposure_us = exposure_.exposure_us;
      d.gain_db = exposure_.gain_db;
      f = render_dot_grid(d, rig_.rig_.simulation, rig_.dot_grids_[index_], id);
    } else {
      std::lock_guard<std::mutex> lock(rig_.scene_mutex_);
      rig_.scene_->set_time(time);
      f = rig_.renderers_[index_]->render(*rig_.scene_, rig_.lighting(), exposure_, id);
    }
    f.frame_id = id;
    f.timestamp_ns = static_cast<int64_t>(time * 1e9);
    return f;
  }

  void fail_after(uint64_t frames, StatusCode code) {
    fail_after_ = answered_ + frames;
    fail_code_ = code;
  }

 private:
  SimulatedRig& rig_;
  size_t index_;
  CameraInfo info_;
  Exposure exposure_;
  uint64_t frame_id_ = 0, answered_ = 0;
  std::optional<uint64_t> fail_after_;
  StatusCode fail_code_ = StatusCode::kDeadlineExceeded;
};

SimulatedRig::~SimulatedRig() = default;

StatusOr<std::unique_ptr<SimulatedRig>> SimulatedRig::create(const RigDescription& rig) {
  TriangleMesh subject;
  if (!rig.simulation.subject.empty()) {
    auto mesh = read_ply_mesh(rig.simulation.subject);
    if (!mesh.ok()) return Status(mesh.status().code(), "the simulated rig's subject: " + mesh.status().message());
    subject = std::move(mesh).value();
  }
  return create(rig, subject);
}

StatusOr<std::unique_ptr<SimulatedRig>> SimulatedRig::create(const RigDescription& rig, const TriangleMesh& subject) {
  std::unique_ptr<SimulatedRig> r(new SimulatedRig());
  r->rig_ = rig;
  if (rig.simulation.posture.any() && !subject.triangles.empty()) {
    ASSIGN_OR_RETURN(const BodyPoser* poser, BodyPoser::shipped());
    StatusOr<PosedBody> posed = poser->pose(subject, rig.simulation.posture);
    if (!posed.ok()) return posed.status().with_context("posing the simulated subject");
    ASSIGN_OR_RETURN(r->scene_, Scene::create(r->rig_, posed->mesh));
  } else {
    ASSIGN_OR_RETURN(r->scene_, Scene::create(r->rig_, subject));
  }
  for (const CameraDescription& c : r->rig_.cameras)
    r->renderers_.push_back(std::make_unique<Renderer>(c, r->rig_.simulation));
  r->controller_ = std::make_unique<SimController>(r->rig_);
  for (size_t i = 0; i < r->rig_.cameras.size(); ++i) {
    r->cameras_.push_back(std::make_unique<SimCamera>(*r, i));
    r->dot_grids_.push_back(dot_grid_for(r->renderers_[i]->model()));
  }
  r->dot_grid_held_.assign(r->rig_.cameras.size(), false);
  return r;
}

Controller& SimulatedRig::controller() { return *controller_; }
Camera& SimulatedRig::camera(size_t i) { return *cameras_.at(i); }

void SimulatedRig::hold_dot_grid(size_t i, bool held) { dot_grid_held_.at(i) = held; }

void SimulatedRig::fail_camera_after(size_t i, uint64_t frames, StatusCode code) {
  cameras_.at(i)->fail_after(frames, code);
}

void SimulatedRig::break_frame_light(const Vec3d& centre) {
  std::lock_guard<std::mutex> lock(scene_mutex_);
  dead_lights_.push_back(centre);
  for (auto& r : renderers_) r->forget_lights();
}

Lighting SimulatedRig::lighting() const {
  Lighting l;
  l.room_lights = controller_->room();
  l.front_frame_lights = controller_->front_lights();
  l.back_frame_lights = controller_->back_lights();
  l.dead_lights = dead_lights_;
  for (size_t i = 0; i < rig_.lasers.size(); ++i) {
    if (controller_->laser_on(static_cast<int>(i))) l.lasers.push_back({&rig_.lasers[i], controller_->step(i)});
  }
  return l;
}

}  // namespace bodyscan::hw::sim
