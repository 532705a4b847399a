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

// The box inside the frames where a subject stands: a tube's width inside the poles'
// inner faces, from just above the floor (the bottom frame stands on it) to the top
// frame.
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
  TriangulationMethod method = TriangulationMethod::kLaserHomography;
  int window_pad_px = 8;
  int smooth_rows = 5;   // smooth_stripe's half window (0: off)
  int min_run_rows = 2;  // drop_short_runs before smoothing (1: keep every sample)
  double floor_line_mm = 3;
  // The angle between a pixel's ray and the laser plane: the depth error is the
  // stripe's error over its sine. Points seen at less than min_angle_deg are dropped;
  // confidence falls in proportion to the sine below full_angle_deg.
  double min_angle_deg = 10;
  double full_angle_deg = 30;  // a sample whose floor point is this near another lit laser's plane is that laser's
};

// Where a frame's points came from, stored with each point.
struct PointSource {
  int camera = kUnknownSource, laser = kUnknownSource, frame = kUnknownSource;
};

// Confidence of a stripe sample from its contrast: 0 at the threshold, 1 from four
// thresholds up.
float stripe_confidence(const StripeSample& s, int threshold);
// Confidence from the triangulation angle (between the ray and the laser plane).
float angle_confidence(double angle_deg, double full_angle_deg);

// The frame's stripe samples where `plane` can meet the subject (stripe_windows), or
// along whole rows when there is no plane yet, as extracted: smooth_stripe them
// (options.smooth_rows) before triangulating. The scan keeps them unsmoothed in its
// raw record, so that a later smoothing can be replayed on them.
StatusOr<std::vector<StripeSample>> extract_plane_stripe(const CameraCalibration& cal, const LaserPlane* plane,
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
