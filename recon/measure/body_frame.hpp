// The body's own frame, found from its surface: which way a standing body faces and
// where it stands on the floor. The landmark rules are written for a body facing
// +Z with its left side at +X; in this frame every body is so, however it turned
// or wherever it stood in the rig.
//
// The vertical is the world's Y (the floor's normal: heights are measured from the
// floor, and the standard's girths are horizontal). The left-right axis is the
// normal of the trunk's plane of mirror symmetry, fitted to horizontal cuts
// between the hips and the chest, where no arm or leg joins the trunk's loop;
// front and back are told apart by the feet, which reach forward of the ankles.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

#include "core/status.hpp"
#include "recon/geometry/triangle_mesh.hpp"

namespace bodyscan {

struct BodyFrame {
  // Body frame: origin on the floor under the trunk's centre, +Y up, +Z the way
  // the body faces, +X its left side. World: the mesh's frame (mm).
  Eigen::Isometry3d world_from_body = Eigen::Isometry3d::Identity();
  double floor_y = 0;  // world, mm
  double height = 0;   // top of the body above the floor, mm
  // The facing's angle about the vertical from world +Z toward world +X, degrees
  // (-180, 180].
  double turn_deg = 0;
  // The trunk's mirror symmetry: RMS distance (mm) of its cuts' points, mirrored
  // in the sagittal plane, from the cuts themselves. A few mm on a person; more
  // means the facing is less sure.
  double asymmetry_rms_mm = 0;
  // How far (mm) the feet reach forward of the ankles on average: the evidence
  // for which side is the front. Under kFeetEvidenceMm the feet do not tell (a
  // scan without them), and the body is taken to face the rig's front (+Z), as
  // the staff place customers.
  double feet_forward_mm = 0;
  bool front_from_feet = true;

  Eigen::Isometry3d body_from_world() const { return world_from_body.inverse(); }
};

inline constexpr double kFeetEvidenceMm = 10;

struct BodyFrameOptions {
  std::optional<double> floor_y;  // default: the mesh's lowest point
};

// Errors when the mesh is not a standing body (under 500 mm tall, no trunk
// between 50 and 70 % of its height).
StatusOr<BodyFrame> find_body_frame(const TriangleMesh& mesh, const BodyFrameOptions& options = {});

// `mesh` moved by `transform` (vertices and normals; faces and confidence kept).
TriangleMesh transformed(const TriangleMesh& mesh, const Eigen::Isometry3d& transform);

}  // namespace bodyscan
