// The simulated rig's world: the subject, the two frames' white tubing, the floor,
// in one Embree scene for ray casting. The subject can move (sway, breathing): the
// scene is refitted to its pose at a given time.
#pragma once

#include <memory>
#include <vector>

#include "core/status.hpp"
#include "hw/rig_description.hpp"
#include "recon/geometry/triangle_mesh.hpp"

namespace bodyscan::hw::sim {

enum class Surface : uint8_t { kNone, kSubject, kFrame, kFloor };

struct Hit {
  Surface surface = Surface::kNone;
  double t = 0;  // distance along the (unit) ray
  Vec3d position = Vec3d::Zero();
  Vec3d normal = Vec3d::Zero();  // unit, facing the ray's origin
};

// The subject's sway at `time_s` (mm): side to side (X) by sway_mm, front to back
// (Z) by half that, 1.3 rad ahead, both at sway_hz. The scene poses the
// subject with it; benchmarks hold a scan's estimated sway against it.
Vec3d subject_sway(const SubjectMotion& motion, double time_s);

class Scene {
 public:
  // Builds the scene for a rig. `subject` may be empty (an empty rig); it is stood
  // on the floor, turned by subject_yaw_deg and moved by subject_offset as the
  // description says.
  static StatusOr<std::unique_ptr<Scene>> create(const RigDescription& rig, const TriangleMesh& subject);
  ~Scene();
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  // Moves the subject to its pose at `time_s` (sway, breathing). Cheap: a refit.
  void set_time(double time_s);
  double time() const { return time_; }
  bool moves() const;
  // Changes whenever the geometry does (a moving subject posed anew), so renderers
  // can keep what they cast for a still scene. Distinct per Scene object.
  uint64_t version() const { return version_; }

  // The nearest surface along origin + t dir, t in (t_min, t_max); dir unit.
  Hit intersect(const Vec3d& origin, const Vec3d& dir, double t_min = 1e-3, double t_max = 1e9) const;
  // True when anything blocks the segment from origin to origin + t_max dir.
  bool occluded(const Vec3d& origin, const Vec3d& dir, double t_max) const;

  // The subject's mesh in its current pose (world mm), e.g. for ground truth.
  const TriangleMesh& subject() const { return posed_; }
  const RigDescription& rig() const { return rig_; }
  double floor_y() const { return -0.5 * rig_.frame.tube; }

 private:
  Scene() = default;
  struct Embree;
  std::unique_ptr<Embree> rt_;
  RigDescription rig_;
  TriangleMesh rest_;                    // the subject at time 0
  TriangleMesh posed_;                   // the subject now
  std::vector<float> breathing_weight_;  // per vertex, 0..1
  Vec3d body_axis_ = Vec3d::Zero();      // a point on the subject's vertical axis
  double time_ = 0;
  uint64_t version_ = 0;
  std::vector<Vec3f> frame_vertices_;
  std::vector<Triangle> frame_triangles_;
};

}  // namespace bodyscan::hw::sim
