// A pinhole camera with Brown-Conrady lens distortion: how a world point becomes a
// pixel, and back. The simulated rig renders with it; the calibration pipeline must
// never see a rig's true models (it finds its own, thesis §3.1), so this lives in
// hw/, not recon/.
//
// Frames: world in mm (Y up). The camera frame has x right, y down and z forward
// along the optical axis, so that pixel x grows with camera x and pixel y with
// camera y (image origin at the top-left pixel's centre, DESIGN.md).
// Distortion acts on normalised coordinates (x, y) = (X/Z, Y/Z):
//   r^2 = x^2 + y^2
//   x_d = x (1 + k1 r^2 + k2 r^4 + k3 r^6) + 2 p1 x y + p2 (r^2 + 2 x^2)
//   y_d = y (1 + k1 r^2 + k2 r^4 + k3 r^6) + p1 (r^2 + 2 y^2) + 2 p2 x y
// and pixel = (fx x_d + cx, fy y_d + cy) - the OpenCV convention, so figures are
// comparable with OpenCV's calibration.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

namespace bodyscan::hw {

using Vec2d = Eigen::Vector2d;
using Vec3d = Eigen::Vector3d;
using Mat3d = Eigen::Matrix3d;

struct Distortion {
  double k1 = 0, k2 = 0, k3 = 0, p1 = 0, p2 = 0;
  bool is_zero() const { return k1 == 0 && k2 == 0 && k3 == 0 && p1 == 0 && p2 == 0; }
};

class CameraModel {
 public:
  CameraModel() = default;
  // world_from_camera: the camera's orientation (columns: its x, y, z axes in world
  // coordinates); centre: its centre of projection, world mm.
  CameraModel(int width, int height, double fx, double fy, double cx, double cy, const Distortion& d,
              const Mat3d& world_from_camera, const Vec3d& centre);

  // A camera at `centre` looking at `target`, image y pointing as far down the
  // world's -Y as the view allows (a level camera), focal length f (mm) on pixels of
  // `pixel_size` (mm), principal point at the image centre.
  static CameraModel look_at(int width, int height, double focal_mm, double pixel_size_mm, const Distortion& d,
                             const Vec3d& centre, const Vec3d& target);

  int width() const { return width_; }
  int height() const { return height_; }
  double fx() const { return fx_; }
  double fy() const { return fy_; }
  double cx() const { return cx_; }
  double cy() const { return cy_; }
  const Distortion& distortion() const { return dist_; }
  const Mat3d& world_from_camera() const { return r_; }
  const Vec3d& centre() const { return c_; }

  // Normalised coordinates -> distorted normalised coordinates.
  Vec2d distort(const Vec2d& undistorted) const;
  // The inverse, by Newton's method from the undistorted guess; nullopt if it does
  // not converge to 1e-12 (far outside the lens's useful field).
  std::optional<Vec2d> undistort(const Vec2d& distorted) const;

  // Pixel of a world point; nullopt when the point is behind the camera.
  std::optional<Vec2d> project(const Vec3d& world) const;
  // Unit ray direction (world) through a pixel, distortion removed; nullopt when
  // the pixel is outside what the distortion model can invert.
  std::optional<Vec3d> ray(const Vec2d& pixel) const;
  // True when the pixel lies on the sensor (within half a pixel of the edge pixels).
  bool in_image(const Vec2d& pixel) const {
    return pixel.x() >= -0.5 && pixel.y() >= -0.5 && pixel.x() <= width_ - 0.5 && pixel.y() <= height_ - 0.5;
  }

 private:
  int width_ = 0, height_ = 0;
  double fx_ = 1, fy_ = 1, cx_ = 0, cy_ = 0;
  Distortion dist_;
  Mat3d r_ = Mat3d::Identity();  // world_from_camera
  Vec3d c_ = Vec3d::Zero();
};

}  // namespace bodyscan::hw
