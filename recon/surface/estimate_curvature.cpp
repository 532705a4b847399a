// Curvature by circle fitting, checked against the normal-angle estimate.
// Thesis §3.2.2.4, eq. 3.20-3.23; Levenberg-Marquardt as in Moré (1978).
//
// The circle is parametrised by a point (0, a) on it, its tangent angle phi there,
// and its signed curvature kappa, so that a flat section (kappa = 0) is an ordinary
// value rather than an infinite radius. With t, s the coordinates of a sample along
// and across the tangent at (0, a), and P = kappa (t^2 + s^2) / 2 - s, the signed
// geometric distance to the circle is 2P / (1 + sqrt(1 + 2 kappa P)) (Pratt 1987;
// Chernov & Lesort 2005), exact and smooth through kappa = 0.
#include "recon/surface/estimate_curvature.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Eigen/Dense>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

namespace bodyscan {

namespace {

struct Residual {
  double r;
  Eigen::Vector3d j;  // d r / d (a, phi, kappa)
};

Residual circle_residual(double u, double h, double a, double phi, double kappa) {
  const double c = std::cos(phi), s_phi = std::sin(phi);
  const double d = h - a;
  const double t = u * c + d * s_phi;
  const double s = -u * s_phi + d * c;
  const double rho2 = t * t + s * s;
  const double p = 0.5 * kappa * rho2 - s;
  const double q = std::sqrt(std::max(0.0, 1.0 + 2.0 * kappa * p));
  const double den = 1.0 + q;
  Residual res;
  res.r = 2.0 * p / den;
  const double q_safe = std::max(q, 1e-12);
  const double dr_dp = (2.0 * den - 2.0 * p * kappa / q_safe) / (den * den);
  const double dr_dk_at_p = -2.0 * p * (p / q_safe) / (den * den);
  const double dp_da = kappa * (-t * s_phi - s * c) + c;
  const double dp_dphi = t;
  res.j = {dr_dp * dp_da, dr_dp * dp_dphi, dr_dp * 0.5 * rho2 + dr_dk_at_p};
  return res;
}

}  // namespace

float fit_circle_curvature(const float* u, const float* h, size_t count, int max_iterations) {
  if (count < 4) return std::numeric_limits<float>::quiet_NaN();
  // Start from the least-squares parabola h = a + b u + c u^2, whose curvature at its
  // vertex region is 2c / (1 + b^2)^1.5: close to the circle for the small arcs a
  // neighbourhood spans, so a few LM steps suffice.
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d atb = Eigen::Vector3d::Zero();
  double scale2 = 0.0;
  for (size_t i = 0; i < count; ++i) {
    const Eigen::Vector3d row(1.0, u[i], static_cast<double>(u[i]) * u[i]);
    ata += row * row.transpose();
    atb += row * h[i];
    scale2 += static_cast<double>(u[i]) * u[i];
  }
  const Eigen::Vector3d coef = ata.ldlt().solve(atb);
  if (!coef.allFinite() || scale2 <= 0.0) return std::numeric_limits<float>::quiet_NaN();
  double a = coef[0];
  double phi = std::atan(coef[1]);
  double kappa = 2.0 * coef[2] / std::pow(1.0 + coef[1] * coef[1], 1.5);

  auto cost_of = [&](double a_, double phi_, double k_) {
    double sum = 0.0;
    for (size_t i = 0; i < count; ++i) {
      const double r = circle_residual(u[i], h[i], a_, phi_, k_).r;
      sum += r * r;
    }
    return sum;
  };
  double cost = cost_of(a, phi, kappa);
  double lambda = 1e-3;
  for (int it = 0; it < max_iterations; ++it) {
    Eigen::Matrix3d jtj = Eigen::Matrix3d::Zero();
    Eigen::Vector3d jtr = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < count; ++i) {
      const Residual res = circle_residual(u[i], h[i], a, phi, kappa);
      jtj += res.j * res.j.transpose();
      jtr += res.j * res.r;
    }
    bool improved = false;
    for (int attempt = 0; attempt < 4 && !improved; ++attempt) {
      Eigen::Matrix3d damped = jtj;
      damped.diagonal() *= (1.0 + lambda);
      damped.diagonal().array() += 1e-12;
      const Eigen::Vector3d step = damped.ldlt().solve(-jtr);
      if (!step.allFinite()) break;
      const double new_cost = cost_of(a + step[0], phi + step[1], kappa + step[2]);
      if (new_cost < cost) {
        a += step[0];
        phi += step[1];
        kappa += step[2];
        improved = cost - new_cost > 1e-12 * cost;
        cost = new_cost;
        lambda = std::max(lambda * 0.3, 1e-9);
        if (!improved) it = max_iterations;  // converged
        improved = true;
      } else {
        lambda *= 10.0;
      }
    }
    if (!improved) break;
  }
  // Signed so that positive = centre on the -n side (surface bends away from n).
  return static_cast<float>(-kappa);
}

float angle_curvature(const Vec3f& p, const Vec3f& n, const std::vector<Vec3f>& points,
                      const std::vector<Vec3f>& normals, const uint32_t* neighbours, size_t count) {
  double sum = 0.0;
  size_t used = 0;
  for (size_t i = 0; i < count; ++i) {
    const uint32_t j = neighbours[i];
    const float dist = (points[j] - p).norm();
    if (dist <= 0.f) continue;
    // Unsigned angle: the estimate must not depend on normal orientation.
    const float cosang = std::min(1.f, std::abs(n.dot(normals[j])));
    const float theta = std::acos(cosang);
    sum += 2.0 * std::sin(0.5 * theta) / dist;  // eq. 3.22
    ++used;
  }
  return used ? static_cast<float>(sum / static_cast<double>(used)) : 0.f;
}

LocalQuadric fit_local_quadric(const std::vector<Vec3f>& points, size_t i, const uint32_t* neighbours, size_t count,
                               const LocalFrames& frames) {
  LocalQuadric q;
  if (count + 1 < 7) return q;
  const Vec3f& p = points[i];
  const Vec3f &t1 = frames.tangent1[i], &t2 = frames.tangent2[i], &nr = frames.normals[i];
  Eigen::Matrix<double, 6, 6> ata = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> atb = Eigen::Matrix<double, 6, 1>::Zero();
  double hh = 0.0;
  for (size_t j = 0; j <= count; ++j) {
    const Vec3f d = j == 0 ? Vec3f::Zero() : Vec3f(points[neighbours[j - 1]] - p);
    const double u = d.dot(t1), v = d.dot(t2), h = d.dot(nr);
    Eigen::Matrix<double, 6, 1> row;
    row << u * u, u * v, v * v, u, v, 1.0;
    ata.selfadjointView<Eigen::Lower>().rankUpdate(row);
    atb += row * h;
    hh += h * h;
  }
  ata.triangularView<Eigen::StrictlyUpper>() = ata.transpose();
  const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(ata);
  if (ldlt.info() != Eigen::Success) return q;
  q.coef = ldlt.solve(atb);
  if (!q.coef.allFinite()) return q;
  // Residual sum of squares of the normal equations' solution: |h|^2 - c . A^T h.
  const double ss = std::max(0.0, hh - q.coef.dot(atb));
  q.residual_rms = std::sqrt(ss / (static_cast<double>(count + 1) - 6.0));
  q.ok = true;
  return q;
}

namespace {

// The shape operator from how the (already smooth, wide-PCA) normals turn across
// the neighbourhood: S (2x2, symmetric, in the tangent plane) is fitted by least
// squares to n_j - n_i = S d_ij over the tangential offsets d_ij. Unlike a
// height-field fit this is not flattened by noise: a noisy shell's nearest
// neighbours sit at similar heights, which biases fitted heights (and so
// curvature) low, but barely moves the normals' turning.
ShapeOperator fit_shape_operator(const std::vector<Vec3f>& points, size_t i, const uint32_t* nb, size_t count,
                                 const LocalFrames& frames) {
  const Vec3f &t1 = frames.tangent1[i], &t2 = frames.tangent2[i], &ni = frames.normals[i];
  // Unknowns (s11, s12, s22); each neighbour gives two equations:
  //   dn1 = s11 u + s12 v,   dn2 = s12 u + s22 v.
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d atb = Eigen::Vector3d::Zero();
  for (size_t j = 0; j < count; ++j) {
    const Vec3f d = points[nb[j]] - points[i];
    const Vec3f dn = frames.normals[nb[j]] - ni;
    const double u = d.dot(t1), v = d.dot(t2);
    const double dn1 = dn.dot(t1), dn2 = dn.dot(t2);
    const Eigen::Vector3d r1(u, v, 0.0), r2(0.0, u, v);
    ata += r1 * r1.transpose() + r2 * r2.transpose();
    atb += r1 * dn1 + r2 * dn2;
  }
  const Eigen::Vector3d sol = ata.ldlt().solve(atb);
  if (!sol.allFinite()) return {};
  return {static_cast<float>(sol[0]), static_cast<float>(sol[1]), static_cast<float>(sol[2])};
}

// Neighbour j's operator read in point i's frame: j's tangent axes are carried into
// i's tangent plane by the smallest rotation taking n_j to n_i (parallel transport
// to first order), so that a cylinder's neighbours add their curvature along the
// same axis instead of losing cos^2 of their frames' tilt.
Eigen::Matrix2f transported(const ShapeOperator& s, const LocalFrames& f, size_t j, size_t i) {
  const Vec3f &nj = f.normals[j], &ni = f.normals[i];
  const float c = nj.dot(ni);
  Eigen::Matrix2f m;
  m << s.s11, s.s12, s.s12, s.s22;
  if (c <= -0.99f) return m;  // opposite sides of a thin sheet: nothing to carry
  const Vec3f axis = nj + ni;
  auto carry = [&](const Vec3f& v) -> Vec3f { return v - (ni.dot(v) / (1.f + c)) * axis; };
  const Vec3f u1 = carry(f.tangent1[j]), u2 = carry(f.tangent2[j]);
  Eigen::Matrix2f r;  // rows: i's axes; columns: j's carried axes
  r << f.tangent1[i].dot(u1), f.tangent1[i].dot(u2), f.tangent2[i].dot(u1), f.tangent2[i].dot(u2);
  return r * m * r.transpose();
}

}  // namespace

LocalFrames correct_normal_tilt(const LocalFrames& pca, const std::vector<ShapeOperator>& shape) {
  const size_t n = pca.normals.size();
  if (pca.offset.size() != n || shape.size() != n) return pca;
  LocalFrames out = pca;
  tbb::parallel_for(size_t{0}, n, [&](size_t i) {
    const Vec3f &t1 = pca.tangent1[i], &t2 = pca.tangent2[i];
    const float u = pca.offset[i].dot(t1), v = pca.offset[i].dot(t2);
    const ShapeOperator& s = shape[i];
    if (!(s.mean() > 0.f)) return;  // a hollow keeps its PCA normal (see the header)
    const Vec3f nr = (pca.normals[i] + (s.s11 * u + s.s12 * v) * t1 + (s.s12 * u + s.s22 * v) * t2).normalized();
    if (!nr.allFinite()) return;
    Vec3f a = t1 - t1.dot(nr) * nr;
    if (a.squaredNorm() < 1e-12f) return;
    a.normalize();
    out.normals[i] = nr;
    out.tangent1[i] = a;
    out.tangent2[i] = nr.cross(a);
  });
  return out;
}

std::vector<ShapeOperator> estimate_shape_operators(const std::vector<Vec3f>& points, const KnnIndex& index,
                                                    const NeighborGraph& graph, const LocalFrames& frames,
                                                    const MeanCurvatureOptions& options) {
  const size_t n = points.size();
  std::vector<ShapeOperator> s(n);
  if (options.k <= graph.k) {
    tbb::parallel_for(size_t{0}, n,
                      [&](size_t i) { s[i] = fit_shape_operator(points, i, graph.row(i), options.k, frames); });
  } else {
    const size_t k = std::min(options.k, n - 1);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 256), [&](const tbb::blocked_range<size_t>& r) {
      std::vector<uint32_t> idx(k + 1);
      std::vector<float> d2(k + 1);
      for (size_t i = r.begin(); i != r.end(); ++i) {
        const size_t got = index.knn(points[i], k + 1, idx.data(), d2.data());
        size_t m = 0;
        for (size_t j = 0; j < got; ++j)
          if (idx[j] != i) idx[m++] = idx[j];
        s[i] = fit_shape_operator(points, i, idx.data(), std::min(m, k), frames);
      }
    });
  }
  // Plain neighbour averages: the estimate's noise falls with every pass while a
  // curvature that varies slowly over a few spacings is kept. Neighbours' frames
  // differ, so each neighbour's operator is carried into the point's frame first.
  const size_t sk = std::min(options.smoothing_k, graph.k);
  std::vector<ShapeOperator> tmp(n);
  for (int pass = 0; pass < options.smoothing_passes && sk > 0; ++pass) {
    tbb::parallel_for(size_t{0}, n, [&](size_t i) {
      Eigen::Matrix2f sum;
      sum << s[i].s11, s[i].s12, s[i].s12, s[i].s22;
      const uint32_t* nb = graph.row(i);
      for (size_t j = 0; j < sk; ++j) sum += transported(s[nb[j]], frames, nb[j], i);
      sum /= static_cast<float>(sk + 1);
      tmp[i] = {sum(0, 0), 0.5f * (sum(0, 1) + sum(1, 0)), sum(1, 1)};
    });
    s.swap(tmp);
  }
  return s;
}

std::vector<float> estimate_mean_curvature(const std::vector<Vec3f>& points, const KnnIndex& index,
                                           const NeighborGraph& graph, const LocalFrames& frames,
                                           const MeanCurvatureOptions& options) {
  const std::vector<ShapeOperator> s = estimate_shape_operators(points, index, graph, frames, options);
  std::vector<float> h(s.size());
  for (size_t i = 0; i < s.size(); ++i) h[i] = s[i].mean();
  return h;
}

CurvatureResult estimate_curvature(const std::vector<Vec3f>& points, const NeighborGraph& graph,
                                   const LocalFrames& frames, const EstimateCurvatureOptions& options) {
  const size_t n = points.size();
  const size_t k = std::min(options.k, graph.k);
  CurvatureResult result;
  result.curvature.resize(n, Eigen::Vector2f::Zero());
  const float sin_plane = std::sin(options.plane_angle);
  std::atomic<size_t> fits{0}, fallbacks{0};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const tbb::blocked_range<size_t>& r) {
    std::vector<float> u, h;
    std::vector<uint32_t> in_plane;
    size_t local_fits = 0, local_fallbacks = 0;
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const Vec3f& p = points[i];
      const Vec3f& nrm = frames.normals[i];
      const uint32_t* nb = graph.row(i);
      float radius = 0.f;
      for (size_t j = 0; j < k; ++j) radius = std::max(radius, graph.row_distances(i)[j]);
      for (int a = 0; a < 2; ++a) {
        const Vec3f& ta = a == 0 ? frames.tangent1[i] : frames.tangent2[i];
        const Vec3f& tb = a == 0 ? frames.tangent2[i] : frames.tangent1[i];
        u.assign(1, 0.f);
        h.assign(1, 0.f);
        in_plane.clear();
        for (size_t j = 0; j < k; ++j) {
          const Vec3f d = points[nb[j]] - p;
          const float len = d.norm();
          if (len <= 0.f || std::abs(d.dot(tb)) > sin_plane * len) continue;
          u.push_back(d.dot(ta));
          h.push_back(d.dot(nrm));
          in_plane.push_back(nb[j]);
        }
        const float c_angle = angle_curvature(p, nrm, points, frames.normals, in_plane.data(), in_plane.size());
        const float c_circle = std::abs(fit_circle_curvature(u.data(), h.data(), u.size(), options.max_iterations));
        const bool unstable =
            !std::isfinite(c_circle) || c_circle > options.instability_ratio * c_angle +
                                                       1.f / (options.instability_ratio * std::max(radius, 1e-30f));
        if (unstable && !in_plane.empty()) {
          result.curvature[i][a] = c_angle;
          ++local_fallbacks;
        } else {
          result.curvature[i][a] = std::isfinite(c_circle) ? c_circle : 0.f;
          ++local_fits;
        }
      }
    }
    fits += local_fits;
    fallbacks += local_fallbacks;
  });
  result.circle_fits_used = fits;
  result.angle_fallbacks = fallbacks;
  return result;
}

}  // namespace bodyscan
