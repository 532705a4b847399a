#include "recon/calib/plane_projection.hpp"

#include <Eigen/Dense>
#include <cmath>

namespace bodyscan {

namespace {

// Hartley normalisation: centroid to the origin, mean distance sqrt(2).
Eigen::Matrix3d normaliser(const std::vector<Eigen::Vector2d>& p) {
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (const auto& q : p) c += q;
  c /= static_cast<double>(p.size());
  double d = 0;
  for (const auto& q : p) d += (q - c).norm();
  d /= static_cast<double>(p.size());
  const double s = d > 0 ? std::sqrt(2.0) / d : 1.0;
  Eigen::Matrix3d t;
  t << s, 0, -s * c.x(), 0, s, -s * c.y(), 0, 0, 1;
  return t;
}

Eigen::Vector2d apply(const Eigen::Matrix3d& h, const Eigen::Vector2d& p) {
  const Eigen::Vector3d q = h * p.homogeneous();
  return q.hnormalized();
}

}  // namespace

StatusOr<Eigen::Matrix3d> fit_homography(const std::vector<Eigen::Vector2d>& from,
                                         const std::vector<Eigen::Vector2d>& to) {
  const size_t n = from.size();
  if (n < 4 || to.size() != n) {
    return invalid_argument("a projective transform needs at least 4 correspondences; got " + std::to_string(n) +
                            " and " + std::to_string(to.size()));
  }
  for (size_t i = 0; i < n; ++i) {
    if (!from[i].allFinite() || !to[i].allFinite()) return invalid_argument("a correspondence is not finite");
  }
  // With exactly four points, no three may lie on a line (the transform would be
  // undetermined); more points are checked by the fit's conditioning below.
  if (n == 4) {
    for (size_t a = 0; a < n; ++a)
      for (size_t b = a + 1; b < n; ++b)
        for (size_t c = b + 1; c < n; ++c) {
          const Eigen::Vector2d u = from[b] - from[a], v = from[c] - from[a];
          if (std::abs(u.x() * v.y() - u.y() * v.x()) < 1e-6 * u.norm() * v.norm()) {
            return invalid_argument(
                "three of the four points lie on one line: the projective transform is undetermined");
          }
        }
  }
  const Eigen::Matrix3d ti = normaliser(from), tp = normaliser(to);
  Eigen::MatrixXd a(2 * n, 9);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d x = apply(ti, from[i]), X = apply(tp, to[i]);
    const int r = static_cast<int>(2 * i);
    a.row(r) << x.x(), x.y(), 1, 0, 0, 0, -X.x() * x.x(), -X.x() * x.y(), -X.x();
    a.row(r + 1) << 0, 0, 0, x.x(), x.y(), 1, -X.y() * x.x(), -X.y() * x.y(), -X.y();
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
  const Eigen::VectorXd hv = svd.matrixV().col(8);
  Eigen::Matrix3d hn;
  hn << hv(0), hv(1), hv(2), hv(3), hv(4), hv(5), hv(6), hv(7), hv(8);
  Eigen::Matrix3d h = tp.inverse() * hn * ti;
  if (!(std::abs(h(2, 2)) > 1e-15) || !h.allFinite()) return invalid_argument("the projective transform is degenerate");
  return Eigen::Matrix3d(h / h(2, 2));
}

Eigen::Vector2d apply_homography(const Eigen::Matrix3d& h, const Eigen::Vector2d& p) { return apply(h, p); }

StatusOr<PlaneProjection> PlaneProjection::fit(const std::vector<Eigen::Vector2d>& image,
                                               const std::vector<Eigen::Vector2d>& plane, double plane_y) {
  ASSIGN_OR_RETURN(const Eigen::Matrix3d h, fit_homography(image, plane));
  const size_t n = image.size();
  PlaneProjection p;
  p.h_ = h;
  p.inv_ = h.inverse();
  p.y_ = plane_y;
  double ss = 0;
  for (size_t i = 0; i < n; ++i) ss += (p.to_image(plane[i]) - image[i]).squaredNorm();
  p.residual_ = std::sqrt(ss / static_cast<double>(n));
  return p;
}

Eigen::Vector3d PlaneProjection::to_plane(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d xz = apply(h_, pixel);
  return {xz.x(), y_, xz.y()};
}

Eigen::Vector2d PlaneProjection::to_image(const Eigen::Vector2d& plane_xz) const { return apply(inv_, plane_xz); }

Ray3 two_plane_ray(const PlaneProjection& top, const PlaneProjection& bottom, const Eigen::Vector2d& pixel) {
  const Eigen::Vector3d a = top.to_plane(pixel), b = bottom.to_plane(pixel);
  return {b, (b - a).normalized()};
}

}  // namespace bodyscan
