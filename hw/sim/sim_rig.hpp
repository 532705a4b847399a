// The simulated rig: cameras and a controller behind the same interfaces as real
// hardware, rendering what the cameras would see of the subject in the frames.
// Ground truth (the scene, the true camera models) is reachable for tests and
// accuracy reports only; calibration and scanning get the Camera and Controller
// interfaces like any backend.
#pragma once

#include <memory>
#include <mutex>
#include <vector>

#include "hw/camera.hpp"
#include "hw/controller.hpp"
#include "hw/sim/dot_grid.hpp"
#include "hw/sim/renderer.hpp"
#include "hw/sim/scene.hpp"

namespace bodyscan::hw::sim {

class SimulatedRig {
 public:
  // Loads the subject named in the description (if any) and builds the scene.
  static StatusOr<std::unique_ptr<SimulatedRig>> create(const RigDescription& rig);
  // With a subject mesh given directly (mm, Y up); the description's subject is ignored.
  static StatusOr<std::unique_ptr<SimulatedRig>> create(const RigDescription& rig, const TriangleMesh& subject);
  ~SimulatedRig();

  const RigDescription& description() const { return rig_; }
  Controller& controller();
  size_t num_cameras() const { return cameras_.size(); }
  Camera& camera(size_t i);

  // Ground truth, for tests and accuracy reports.
  const Scene& scene() const { return *scene_; }
  const Renderer& renderer(size_t camera) const { return *renderers_[camera]; }

  // The operator holds the lens-calibration dot grid (dot_grid_for) in front of
  // camera `i`: until taken away, that camera's frames show the board.
  void hold_dot_grid(size_t i, bool held);
  const DotGridTarget& dot_grid(size_t i) const { return dot_grids_.at(i); }

  // Fault injection: camera `i` answers `frames` more grabs, then fails every grab
  // with `code` (kDeadlineExceeded: stops answering; kUnavailable: unplugged).
  void fail_camera_after(size_t i, uint64_t frames, StatusCode code);
  // Fault injection: the frame light centred at `centre` (visible_lights) stays dark.
  void break_frame_light(const Vec3d& centre);

 private:
  SimulatedRig() = default;
  class SimController;
  class SimCamera;
  friend class SimCamera;
  Lighting lighting() const;  // from the controller's state

  RigDescription rig_;
  std::unique_ptr<Scene> scene_;
  std::vector<std::unique_ptr<Renderer>> renderers_;
  std::unique_ptr<SimController> controller_;
  std::vector<std::unique_ptr<SimCamera>> cameras_;
  std::vector<DotGridTarget> dot_grids_;
  std::vector<bool> dot_grid_held_;
  std::vector<Vec3d> dead_lights_;
  mutable std::mutex scene_mutex_;  // the scene is posed per grab
};

}  // namespace bodyscan::hw::sim
