#include "recon/scan/laser_sweep.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <set>

namespace bodyscan {

namespace {

// The sweep's parameters as a vector for Gauss-Newton: a small rotation of the axis
// (2), the axis point's move across it (2), theta0, dtheta.
struct Frame {
  Eigen::Vector3d u, e1, e2, a;
  double theta0, dtheta;

  Frame perturbed(const Eigen::Matrix<double, 6, 1>& p) const {
    Frame f = *this;
    // Turn the axis (and its basis) by p(0) about e1 and p(1) about e2.
    const Eigen::Matrix3d r = (Eigen::AngleAxisd(p(0), e1) * Eigen::AngleAxisd(p(1), e2)).toRotationMatrix();
    f.u = (r * u).normalized();
    f.e1 = (r * e1 - (r * e1).dot(f.u) * f.u).normalized();
    f.e2 = f.u.cross(f.e1);
    f.a = a + p(2) * e1 + p(3) * e2;
    f.theta0 = theta0 + p(4);
    f.dtheta = dtheta + p(5);
    return f;
  }
  double residual(const SweepPoint& q) const {
    const double t = theta0 + dtheta * q.step;
    const Eigen::Vector3d n = std::cos(t) * e1 + std::sin(t) * e2;
    return n.dot(q.world - a);
  }
};

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

}  // namespace

StatusOr<LaserSweep> LaserSweep::fit(const std::vector<SweepPoint>& points,
                                     const std::vector<std::pair<int, SweepPlane>>& initial, double reject_mm) {
  std::set<int> steps;
  for (const SweepPoint& p : points) steps.insert(p.step);
  std::set<int> initial_steps;
  for (const auto& [s, pl] : initial) initial_steps.insert(s);
  if (steps.size() < 3 || initial_steps.size() < 2) {
    return failed_precondition("a laser sweep needs points at 3 or more steps (got " + std::to_string(steps.size()) +
                               ") and planes at 2 or more");
  }
  // Start: the axis is the direction all planes contain (least-squares null vector of
  // their normals), the angles a line in the step, the axis point the one nearest all planes.
  std::vector<std::pair<int, SweepPlane>> planes = initial;
  for (auto& [s, pl] : planes)
    if (pl.normal.dot(planes[0].second.normal) < 0) pl.normal = -pl.normal, pl.offset = -pl.offset;
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  for (const auto& [s, pl] : planes) m += pl.normal * pl.normal.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(m);
  Frame f;
  f.u = es.eigenvectors().col(0);
  f.e1 = (planes[0].second.normal - planes[0].second.normal.dot(f.u) * f.u).normalized();
  f.e2 = f.u.cross(f.e1);
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  Eigen::Matrix2d ata = Eigen::Matrix2d::Zero();
  Eigen::Vector2d atb = Eigen::Vector2d::Zero();
  for (const auto& [s, pl] : planes) {
    const double t = std::atan2(pl.normal.dot(f.e2), pl.normal.dot(f.e1));
    sx += s, sy += t, sxx += double(s) * s, sxy += s * t;
    const Eigen::Vector2d row(pl.normal.dot(f.e1), pl.normal.dot(f.e2));
    ata += row * row.transpose();
    atb += row * pl.offset;
  }
  const double n = static_cast<double>(planes.size());
  const double denom = n * sxx - sx * sx;
  f.dtheta = denom != 0 ? (n * sxy - sx * sy) / denom : 0;
  f.theta0 = (sy - f.dtheta * sx) / n;
  const Eigen::Vector2d a2 = ata.ldlt().solve(atb);
  f.a = a2.x() * f.e1 + a2.y() * f.e2;
  if (!f.a.allFinite() || !std::isfinite(f.theta0) || !std::isfinite(f.dtheta)) {
    return failed_precondition("the laser's planes do not share an axis");
  }

  // Gauss-Newton on the points' distances to their step's plane. First with Huber
  // weights (a pole point caught on the wrong face or a stray reflection pulls no
  // harder than one a few robust sigmas off), keeping the points within `reject_mm`
  // or 4 robust sigmas of the fit and refitting until that set settles (a point
  // wrongly left out early comes back); then plain least squares on the kept points.
  // A step that raises the cost is halved.
  std::vector<const SweepPoint*> use;
  for (const SweepPoint& p : points) use.push_back(&p);
  const auto robust_sigma = [&](const Frame& fr) {
    std::vector<double> abs_r;
    abs_r.reserve(use.size());
    for (const SweepPoint* q : use) abs_r.push_back(std::abs(fr.residual(*q)));
    return 1.4826 * median(abs_r);
  };
  constexpr int kRobustRounds = 6;
  for (int round = 0; round <= kRobustRounds; ++round) {
    const bool robust = round < kRobustRounds;
    for (int iter = 0; iter < 12; ++iter) {
      const double c = robust ? std::max(0.5 * reject_mm, 2 * robust_sigma(f)) : 0;
      const auto weight = [c](double r) { return c > 0 && std::abs(r) > c ? c / std::abs(r) : 1.0; };
      const auto cost = [&](const Frame& fr) {
        double sum = 0;
        for (const SweepPoint* q : use) {
          const double r = std::abs(fr.residual(*q));
          sum += c > 0 && r > c ? c * (2 * r - c) : r * r;  // Huber
        }
        return sum;
      };
      Eigen::Matrix<double, 6, 6> jtj = Eigen::Matrix<double, 6, 6>::Zero();
      Eigen::Matrix<double, 6, 1> jtr = Eigen::Matrix<double, 6, 1>::Zero();
      const double h[6] = {1e-6, 1e-6, 1e-3, 1e-3, 1e-6, 1e-8};
      Frame plus[6];
      for (int k = 0; k < 6; ++k) {
        Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
        d(k) = h[k];
        plus[k] = f.perturbed(d);
      }
      for (const SweepPoint* q : use) {
        const double r = f.residual(*q);
        const double w = weight(r);
        Eigen::Matrix<double, 6, 1> j;
        for (int k = 0; k < 6; ++k) j(k) = (plus[k].residual(*q) - r) / h[k];
        jtj += w * j * j.transpose();
        jtr += w * j * r;
      }
      Eigen::Matrix<double, 6, 1> step = -jtj.ldlt().solve(jtr);
      if (!step.allFinite()) break;
      const double before = cost(f);
      Frame next = f.perturbed(step);
      double after = cost(next);
      for (int halve = 0; halve < 6 && after > before; ++halve) {
        step *= 0.5;
        next = f.perturbed(step);
        after = cost(next);
      }
      if (after > before) break;
      f = next;
      if (step.cwiseAbs().maxCoeff() < 1e-12) break;
    }
    if (!robust) break;
    const double limit = std::max(reject_mm, 4 * robust_sigma(f));
    std::vector<const SweepPoint*> kept;
    for (const SweepPoint& q : points)
      if (std::abs(f.residual(q)) <= limit) kept.push_back(&q);
    const bool settled = kept == use;
    use.swap(kept);
    if (settled) round = kRobustRounds - 1;  // straight to the plain fit
  }
  LaserSweep out;
  out.u_ = f.u, out.e1_ = f.e1, out.e2_ = f.e2, out.a_ = f.a, out.theta0_ = f.theta0, out.dtheta_ = f.dtheta;
  double ss = 0;
  for (const SweepPoint* q : use) ss += f.residual(*q) * f.residual(*q);
  out.used_ = use.size();
  out.rejected_ = points.size() - use.size();
  out.rms_ = use.empty() ? 0 : std::sqrt(ss / static_cast<double>(use.size()));
  return out;
}

SweepPlane LaserSweep::plane(int step) const {
  const double t = theta0_ + dtheta_ * step;
  SweepPlane p;
  p.normal = std::cos(t) * e1_ + std::sin(t) * e2_;
  p.offset = p.normal.dot(a_);
  return p;
}

double LaserSweep::degrees_per_step() const { return dtheta_ * 180.0 / M_PI; }

}  // namespace bodyscan
