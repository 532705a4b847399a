// How far a cloud lies from a true surface once it is moved by the one translation
// that fits it best: the measure of a scan whose subject moved: where the body
// stood on average is unknowable but its shape is not.
#pragma once

#include <Eigen/Dense>
#include <cmath>

#include "recon/geometry/mesh_distance.hpp"

namespace bodyscan::testing {

// RMS signed distance (mm) of every `stride`-th point to `truth` after the best
// translation (point-to-plane, four rounds). Points farther than `outlier_mm` from
// the truth are not on it (a stray reflection) and are left out.
inline double rms_distance_after_shift(const PointCloud& cloud, const MeshDistance& truth, size_t stride = 4,
                                       float outlier_mm = 10) {
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  double rms = 0;
  for (int it = 0; it < 4; ++it) {
    Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    double ss = 0;
    size_t n = 0;
    for (size_t i = 0; i < cloud.size(); i += stride) {
      const Vec3f q = cloud.positions[i] - shift.cast<float>();
      const ClosestPoint c = truth.closest_point(q);
      if (c.distance < 1e-4f || c.distance > outlier_mm) continue;
      const Eigen::Vector3d normal = ((q - c.point) / c.distance * (c.signed_distance < 0 ? -1.f : 1.f)).cast<double>();
      a += normal * normal.transpose();
      b += normal * c.signed_distance;
      ss += c.signed_distance * c.signed_distance;
      ++n;
    }
    if (n == 0) return 0;
    shift += a.ldlt().solve(b);
    rms = std::sqrt(ss / static_cast<double>(n));
  }
  return rms;
}

}  // namespace bodyscan::testing
