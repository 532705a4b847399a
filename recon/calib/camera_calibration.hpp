// One camera's calibration from what it sees (thesis §3.1.1-3.1.2): its lens
// correction (from the dot grid), which side of the frame it faces, its eight
// frame markers named, and the image -> bottom-plane and image -> top-plane
// projective transforms. Nothing about where the camera stands is given; its centre
// of projection comes out as the point the two-plane rays meet.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/status.hpp"
#include "recon/calib/frame_markers.hpp"
#include "recon/calib/lens_correction.hpp"
#include "recon/calib/plane_projection.hpp"
#include "recon/calib/reference_frame.hpp"

namespace bodyscan {

struct CameraCalibration {
  std::string camera_id;
  int width = 0, height = 0;
  ReferenceFrame frame;
  LensCorrection lens;
  FrameSide side = FrameSide::kFront;
  // Per pole (indexed by Pole), the lens-corrected images of its two lights in
  // light_x order.
  std::array<std::array<Eigen::Vector2d, 2>, 4> markers{};
  PlaneProjection bottom, top;
  // Where the two-plane rays meet (least squares over the image's top and bottom
  // bands), world mm, and their RMS distance from it: 0 for a perfect pinhole after
  // lens correction, so a check on the lens correction and the markers together.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double ray_spread_mm = 0;
  Eigen::Vector3d forward = Eigen::Vector3d::UnitZ();  // roughly where the camera looks

  const PlaneProjection& projection(Pole p) const { return is_top(p) ? top : bottom; }
  // The world ray of a lens-corrected pixel: from the centre towards its top- and
  // bottom-plane points (averaged), in homogeneous form so that rows near the
  // horizon, whose plane points lie far off, keep their accuracy.
  Ray3 ray(const Eigen::Vector2d& corrected) const;
};

// The side of the frame a camera faces, from its eight markers (all lights on) and
// the blobs it sees with only the front poles' lights on: a front camera then sees
// its near poles' lights (the outer pair of each frame's four), a back camera its
// far poles'. Errors say what was seen instead.
StatusOr<FrameSide> identify_side(const FrameMarkers& all_lights, const std::vector<Marker>& front_lights);

// The eight markers named: per frame, the near pole's pair lies farther from the
// image's horizon (lower for the bottom frame, higher for the top), and its lights
// are put in world X order (image left to right is +X for a front camera, -X for a
// back one; cameras stand level). Pixels as given (raw or corrected).
std::array<std::array<Eigen::Vector2d, 2>, 4> name_markers(const FrameMarkers& markers, FrameSide side);

struct CameraCalibrationImages {
  ImageView lights_off;    // room lights and frame lights off
  ImageView lights_on;     // both frame-light circuits on
  ImageView front_lights;  // the front poles' circuit only
};

// Markers, side, plane transforms and centre for one camera whose lens correction is
// already known. Errors name the camera and the step that failed.
StatusOr<CameraCalibration> calibrate_camera(const std::string& camera_id, const LensCorrection& lens,
                                             const CameraCalibrationImages& images, const ReferenceFrame& frame,
                                             const MarkerOptions& options = {});

// The rest of a camera's calibration from its named, lens-corrected markers: the
// plane transforms, the centre, the view. calibrate_camera ends here; a scan's raw
// record (docs/archive.md) rebuilds its cameras with it, exactly.
StatusOr<CameraCalibration> camera_from_markers(const std::string& camera_id, int width, int height,
                                                const ReferenceFrame& frame, const LensCorrection& lens, FrameSide side,
                                                const std::array<std::array<Eigen::Vector2d, 2>, 4>& markers);

}  // namespace bodyscan
