// A point cloud as the scanner produces it: positions plus optional per-point
// attributes. Structure of arrays: an attribute vector is either empty (absent) or
// has exactly one entry per point.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

namespace bodyscan {

using Vec3f = Eigen::Vector3f;
using Vec3d = Eigen::Vector3d;

// Marks a point whose camera / laser / frame is not known.
inline constexpr int32_t kUnknownSource = -1;

struct PointCloud {
  // mm, world frame (Y up).
  std::vector<Vec3f> positions;
  // Unit normals pointing out of the body, world frame. Empty if not known.
  std::vector<Vec3f> normals;
  // Stripe peak intensity, arbitrary units (0..1 for 8-bit data). Empty if not known.
  std::vector<float> intensity;
  // Confidence in [0, 1]: how much the point should pull the surface. Empty = all 1.
  std::vector<float> confidence;
  // Where each point came from. Empty if not known; entries may be kUnknownSource.
  std::vector<int32_t> camera;
  std::vector<int32_t> laser;
  std::vector<int32_t> frame;
  // Centre of projection of camera c, mm, world frame, indexed by the `camera` ids.
  // Lets normals be oriented toward the viewpoint that saw each point.
  std::vector<Vec3f> camera_centres;

  size_t size() const { return positions.size(); }
  bool empty() const { return positions.empty(); }
  bool has_normals() const { return !normals.empty(); }
  bool has_confidence() const { return !confidence.empty(); }
  bool has_cameras() const { return !camera.empty() && !camera_centres.empty(); }

  // True when every present attribute has one entry per point and every camera id
  // is either kUnknownSource or indexes camera_centres.
  bool is_consistent() const;

  // Removes the points whose `drop` entry is non-zero (one entry per point), keeping
  // every attribute in step and the rest in order. Returns how many went.
  size_t remove_points(const std::vector<uint8_t>& drop);
};

}  // namespace bodyscan
