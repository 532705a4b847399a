// Stripe pixels to 3-D points (thesis §3.1.4): per frame, each row's stripe sample
// (searched only where the laser plane can meet the subject), lens-corrected, taken
// to the laser plane, kept if it lands inside the frame, with where it came from and
// how far to trust it.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "recon/calib/camera_calibration.hpp"
#include "recon/geometry/point_cloud.hpp"
#include "recon/scan/laser_plane.hpp"
#include "recon/scan/laser_sweep.hpp"
#include "recon/scan/stripe.hpp"

namespace bodyscan {

// The box inside the frames where a subject stands: between the poles' inner faces,
// from just above the floor (the bottom frame stands on it) to the top frame.
struct ScanVolume {
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
  bool contains(const Eigen::Vector3d& p) const {
    return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
  }
};
ScanVolume scan_volume(const ReferenceFrame& frame);

// Per image row, the raw columns where the plane's part inside `volume` images,
// widened by `pad` pixels; empty where it does not.
std::vector<ColumnRange> stripe_windows(const CameraCalibration& cal, const LaserPlane& plane, const ScanVolume& volume,
                                        int pad);

struct TriangulateOptions {
  StripeOptions stripe;
  TriangulationMethod method = TriangulationMethod::kTwoPlaneRay;
  int window_pad_px = 8;
  double floor_line_mm = 3;  // a sample whose floor point is this near another lit laser's plane is that laser's
};

// Where a frame's points came from, stored with each point.
struct PointSource {
  int camera = kUnknownSource, laser = kUnknownSource, frame = kUnknownSource;
};

// Confidence of a stripe sample from its contrast: 0 at the threshold, 1 from four
// thresholds up.
float stripe_confidence(const StripeSample& s, int threshold);

// The frame's stripe samples where `plane` can meet the subject (stripe_windows).
StatusOr<std::vector<StripeSample>> extract_plane_stripe(const CameraCalibration& cal, const LaserPlane& plane,
                                                         const ImageView& frame, const ImageView& base, int full_scale,
                                                         const TriangulateOptions& options);

// Appends the samples' points to `cloud` (positions, intensity, confidence, camera,
// laser, frame; the attribute vectors must be in step) and returns how many. Points
// outside the scan volume are dropped, and so are samples that are the floor line of
// another laser lit at the same time (`others`): the pixel sees the floor where
// that laser's plane meets it.
size_t triangulate_samples(const CameraCalibration& cal, const LaserPlane& plane,
                           const std::vector<StripeSample>& samples, int full_scale, const PointSource& source,
                           const TriangulateOptions& options, const std::vector<SweepPlane>& others, PointCloud* cloud);

}  // namespace bodyscan
