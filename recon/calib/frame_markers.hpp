// The frame markers (thesis §3.1.2): the frame lights seen by one camera, found as
// the bright blobs of (lights on - lights off), thresholded, split into connected
// components, each reduced to its intensity-weighted centroid; then the eight
// expected (four per frame on the side the camera faces) put in order.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "core/status.hpp"
#include "recon/scan/stripe.hpp"  // ImageView

namespace bodyscan {

struct Marker {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();  // intensity-weighted, pixels
  int area = 0;                                      // pixels above the threshold
  double mass = 0;                                   // summed intensity above the off image
};

struct MarkerOptions {
  int threshold = 40;    // on - off, pixel values
  int min_area = 3;      // smaller blobs are noise
  int max_area = 20000;  // larger ones are not a light (a lamp, a reflection)
};

// Every blob of the difference image, largest mass first.
StatusOr<std::vector<Marker>> find_markers(const ImageView& lights_on, const ImageView& lights_off,
                                           const MarkerOptions& options = {});

// The eight markers in image order: the top frame's four (smaller image y, the
// camera being level) left to right, then the bottom frame's four left to right.
// An error says how many were found when that is not eight, so an operator can
// tell a light that stayed off from a stray reflection.
struct FrameMarkers {
  std::array<Eigen::Vector2d, 4> top, bottom;
};
StatusOr<FrameMarkers> order_frame_markers(const std::vector<Marker>& markers);

}  // namespace bodyscan
