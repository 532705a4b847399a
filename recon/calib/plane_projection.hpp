// Image <-> frame-plane projective transforms (thesis §3.1.2, eq. 3.3-3.4, 3.7) and
// the two-plane ray a pixel defines.
//
// Each frame's lights lie in a horizontal plane (Y = 0 for the bottom frame, Y = H
// for the top one). Between (lens-corrected) image coordinates and that plane's
// (X, Z) a homography holds; the thesis writes it as a 4x3 matrix to (X, Y, Z, W)
// with Y fixed, which is the same thing. Four or more correspondences fit it by
// least squares (normalised DLT, Hartley); with both frames' transforms, a pixel's
// 3-D ray is the line through its top-plane and bottom-plane points - the camera's
// centre and orientation never need to be known.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/status.hpp"

namespace bodyscan {

// The projective transform (h(2,2) = 1) taking `from` to `to`, by least squares over
// >= 4 correspondences in general position (normalised DLT). Errors: too few points,
// three of four in a line, non-finite or degenerate input.
StatusOr<Eigen::Matrix3d> fit_homography(const std::vector<Eigen::Vector2d>& from,
                                         const std::vector<Eigen::Vector2d>& to);
Eigen::Vector2d apply_homography(const Eigen::Matrix3d& h, const Eigen::Vector2d& p);

class PlaneProjection {
 public:
  PlaneProjection() = default;
  // Fits image -> (X, Z) on the plane Y = `plane_y` from >= 4 correspondences in
  // general position. Errors: too few points, three or more in a line, non-finite.
  static StatusOr<PlaneProjection> fit(const std::vector<Eigen::Vector2d>& image,
                                       const std::vector<Eigen::Vector2d>& plane_xz, double plane_y);

  // The world point (X, plane_y, Z) a pixel sees on the plane.
  Eigen::Vector3d to_plane(const Eigen::Vector2d& pixel) const;
  // The pixel a point of the plane images at (eq. 3.7's inverse projection).
  Eigen::Vector2d to_image(const Eigen::Vector2d& plane_xz) const;
  double plane_y() const { return y_; }
  const Eigen::Matrix3d& homography() const { return h_; }  // image -> plane, h(2,2) = 1
  // RMS distance (pixels) between the fitted images of the plane points and the
  // measured ones: 0 for exactly 4 points, a check with more.
  double residual_px() const { return residual_; }

 private:
  Eigen::Matrix3d h_ = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d inv_ = Eigen::Matrix3d::Identity();
  double y_ = 0;
  double residual_ = 0;
};

// A pixel's ray in the world: through its bottom-plane and top-plane points.
struct Ray3 {
  Eigen::Vector3d origin, direction;  // direction unit, pointing from top to bottom plane
};
Ray3 two_plane_ray(const PlaneProjection& top, const PlaneProjection& bottom, const Eigen::Vector2d& pixel);

}  // namespace bodyscan
