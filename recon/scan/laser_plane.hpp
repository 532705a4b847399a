// The laser plane of one frame, from the stripe it draws on the frame's poles
// (thesis §3.1.3). Each pole the camera sees is a line in the image through its two
// lights; the stripe's crossing of that line, found like a stripe in a row (the
// brightest place, then the intensity-weighted centroid), maps through the
// bottom- or top-plane transform to a 3-D point on the pole. Three points fix the
// plane; a fourth (the far bottom pole, which the subject may hide) is measured when
// it agrees with them and otherwise estimated where the plane cuts that pole
// (eq. 3.8-3.9).
//
// Two ways then take a stripe pixel to 3-D:
//  - the thesis's: a projective transform from the image to the laser plane fitted
//    to the four pole points (eq. 3.6; a hidden one is put in the image by the
//    inverse bottom-plane transform, eq. 3.7);
//  - the two-plane ray: the pixel's ray through its top- and bottom-plane points
//    (the camera's own calibration), met with the plane.
// docs/scan-processing.md compares them on the simulated rig.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "core/status.hpp"
#include "recon/calib/camera_calibration.hpp"
#include "recon/scan/stripe.hpp"

namespace bodyscan {

enum class TriangulationMethod { kTwoPlaneRay, kLaserHomography };
const char* to_string(TriangulationMethod m);

struct PoleStripe {
  bool found = false;                               // the stripe crosses the pole's line in the image
  bool used = false;                                // it fixes the plane
  bool estimated = false;                           // hidden or disagreeing: put where the plane cuts the pole
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // lens-corrected
  Eigen::Vector3d world = Eigen::Vector3d::Zero();
  double peak = 0;  // frame - base at the crossing, pixel values
};

struct LaserPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();  // unit; normal . x = offset on the plane
  double offset = 0;
  std::array<PoleStripe, 4> poles{};  // indexed by Pole
  // With all four poles measured: the distance (mm) of the far bottom point from the
  // plane of the other three, a check on the whole calibration. Negative otherwise.
  double fourth_point_mm = -1;
  // Eq. 3.6: lens-corrected pixel -> (a, b), the point origin + a * axis_a + b * axis_b.
  Eigen::Matrix3d image_to_plane = Eigen::Matrix3d::Identity();
  Eigen::Vector3d origin = Eigen::Vector3d::Zero(), axis_a = Eigen::Vector3d::UnitY(),
                  axis_b = Eigen::Vector3d::UnitZ();

  Eigen::Vector3d triangulate(const CameraCalibration& cal, const Eigen::Vector2d& corrected,
                              TriangulationMethod method) const;
  // Where a ray meets the plane.
  Eigen::Vector3d intersect(const Ray3& r) const {
    return r.origin + (offset - normal.dot(r.origin)) / normal.dot(r.direction) * r.direction;
  }
  // The lens-corrected pixel of a point of the plane (inverse of eq. 3.6).
  Eigen::Vector2d to_image(const Eigen::Vector3d& on_plane) const;
};

struct LaserPlaneOptions {
  int threshold = 20;           // minimum stripe peak on a pole, frame - base
  double band_px = 2;           // half-width across the pole's line averaged over
  double step_px = 0.5;         // sampling step along the line
  double radius_px = 3;         // centroid half-window along the line
  double max_off_plane_mm = 4;  // a far bottom point farther from the other three's plane is taken as hidden
};

// Sets `plane` to the plane normal . x = offset as this camera sees it: the points
// where it cuts the poles it was not measured on (eq. 3.8-3.9, marked estimated) and
// their images (eq. 3.7), and the image-to-plane transform (eq. 3.6). Pole points
// already marked used are kept.
Status complete_plane(const CameraCalibration& cal, const Eigen::Vector3d& normal, double offset, LaserPlane* plane);

// Built once per camera calibration: where each pole's line lies in the raw image.
class LaserPlaneFinder {
 public:
  LaserPlaneFinder(const CameraCalibration& cal, const LaserPlaneOptions& options = {});
  // Errors (failed_precondition) when the stripe crosses fewer than three poles,
  // naming the poles where it was not found.
  StatusOr<LaserPlane> find(const ImageView& frame, const ImageView& base) const;

 private:
  struct Line {
    Eigen::Vector2d a, b;              // lens-corrected ends (the pole's ends)
    std::vector<Eigen::Vector2f> raw;  // samples x band offsets, raw pixels
    int samples = 0, band = 0;
  };
  const CameraCalibration& cal_;
  LaserPlaneOptions options_;
  std::array<Line, 4> lines_;
};

}  // namespace bodyscan
