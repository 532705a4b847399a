// Points seen at a grazing angle. Towards a body's outline the camera sees the skin
// edge-on: a pixel there spans a steep stretch of surface, the stripe's light is
// spread thinner across it, and the stripe's brightest point moves to the side that
// faces the camera more. The point then lands inside the body, the more so the more
// oblique the view (measured on the simulated rig, docs/scan-processing.md: about
// 0.6 mm at 60-70 degrees from the normal, 1.3 mm at 70-75, 2 mm beyond), a bias no
// averaging removes. Once the cloud has normals (thesis ch. 6 asks for the angle in
// the confidence), such points are dropped and the rest weighted by how squarely
// their camera saw them, so the redundancy rule prefers the better view.
#pragma once

#include <cstddef>

#include "recon/geometry/point_cloud.hpp"

namespace bodyscan {

struct ViewAngleOptions {
  size_t k = 16;              // neighbours in each point's normal (PCA)
  double max_view_deg = 70;   // points seen more obliquely than this are dropped
  double full_view_deg = 45;  // confidence falls with cos(view) beyond this
};

struct ViewAngleResult {
  size_t dropped = 0;
};

// Needs each point's camera and the camera centres (PointCloud::has_cameras).
// Estimates normals (PCA of the k nearest points), turns each towards its point's
// camera and stores them in cloud.normals; drops the points seen beyond
// max_view_deg; scales the others' confidence by min(1, cos(view) / cos(full_view)).
// A cloud without cameras or with fewer than k + 1 points is left as it is.
ViewAngleResult weigh_by_view_angle(PointCloud& cloud, const ViewAngleOptions& options = {});

}  // namespace bodyscan
