#include "hw/camera_model.hpp"

#include <cmath>

namespace bodyscan::hw {

CameraModel::CameraModel(int width, int height, double fx, double fy, double cx, double cy, const Distortion& d,
                         const Mat3d& world_from_camera, const Vec3d& centre)
    : width_(width), height_(height), fx_(fx), fy_(fy), cx_(cx), cy_(cy), dist_(d), r_(world_from_camera), c_(centre) {}

CameraModel CameraModel::look_at(int width, int height, double focal_mm, double pixel_size_mm, const Distortion& d,
                                 const Vec3d& centre, const Vec3d& target) {
  const Vec3d z = (target - centre).normalized();
  // Image y is "down": the world's -Y made orthogonal to the view direction.
  Vec3d down = -Vec3d::UnitY() + z.y() * z;
  if (down.norm() < 1e-9) down = Vec3d::UnitZ();  // looking straight up or down
  const Vec3d y = down.normalized();
  const Vec3d x = y.cross(z);
  Mat3d r;
  r.col(0) = x;
  r.col(1) = y;
  r.col(2) = z;
  const double f = focal_mm / pixel_size_mm;
  return CameraModel(width, height, f, f, 0.5 * (width - 1), 0.5 * (height - 1), d, r, centre);
}

namespace {

// The distortion polynomial at (x, y), with its radial factor (undistort needs it too).
struct Distorted {
  double x, y, radial;
};
Distorted distort_xy(const Distortion& d, double x, double y) {
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (d.k1 + r2 * (d.k2 + r2 * d.k3));
  return {x * radial + 2 * d.p1 * x * y + d.p2 * (r2 + 2 * x * x),
          y * radial + d.p1 * (r2 + 2 * y * y) + 2 * d.p2 * x * y, radial};
}

}  // namespace

Vec2d CameraModel::distort(const Vec2d& u) const {
  const Distorted d = distort_xy(dist_, u.x(), u.y());
  return {d.x, d.y};
}

std::optional<Vec2d> CameraModel::undistort(const Vec2d& d) const {
  if (dist_.is_zero()) return d;
  // Plain scalars rather than Eigen's 2x2 types: every simulated frame undistorts
  // each pixel, and a build that does not inline Eigen (the sanitizers') spends
  // most of its time here otherwise.
  const double k1 = dist_.k1, k2 = dist_.k2, k3 = dist_.k3, p1 = dist_.p1, p2 = dist_.p2;
  double x = d.x(), y = d.y();
  for (int it = 0; it < 50; ++it) {
    const double r2 = x * x + y * y;
    const Distorted at = distort_xy(dist_, x, y);
    const double radial = at.radial;
    const double dradial = k1 + r2 * (2 * k2 + 3 * r2 * k3);  // d radial / d r2
    const double fx = at.x - d.x(), fy = at.y - d.y();
    const double j00 = radial + 2 * x * x * dradial + 2 * p1 * y + 6 * p2 * x;
    const double j01 = 2 * x * y * dradial + 2 * p1 * x + 2 * p2 * y;
    const double j11 = radial + 2 * y * y * dradial + 6 * p1 * y + 2 * p2 * x;
    const double det = j00 * j11 - j01 * j01;  // the Jacobian is symmetric
    if (std::sqrt(fx * fx + fy * fy) < 1e-13) {
      // A root past the lens's fold (where the image radius turns back) is not the
      // point that was imaged: there the mapping is no longer one-to-one.
      if (radial > 0 && det > 0) return Vec2d(x, y);
      return std::nullopt;
    }
    if (!(std::abs(det) > 1e-12)) return std::nullopt;
    x -= (j11 * fx - j01 * fy) / det;
    y -= (j00 * fy - j01 * fx) / det;
    if (!std::isfinite(x) || !std::isfinite(y) || std::sqrt(x * x + y * y) > 100) return std::nullopt;
  }
  return std::nullopt;
}

std::optional<Vec2d> CameraModel::project(const Vec3d& world) const {
  const Vec3d p = r_.transpose() * (world - c_);
  if (!(p.z() > 0)) return std::nullopt;
  const Vec2d d = distort({p.x() / p.z(), p.y() / p.z()});
  return Vec2d(fx_ * d.x() + cx_, fy_ * d.y() + cy_);
}

std::optional<Vec3d> CameraModel::ray(const Vec2d& pixel) const {
  const std::optional<Vec2d> u = undistort({(pixel.x() - cx_) / fx_, (pixel.y() - cy_) / fy_});
  if (!u) return std::nullopt;
  return (r_ * Vec3d(u->x(), u->y(), 1.0)).normalized();
}

}  // namespace bodyscan::hw
