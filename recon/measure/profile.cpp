#include "recon/measure/profile.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <functional>

namespace bodyscan {

double bisect(double lo, double hi, const std::function<bool(double)>& pred, double tol) {
  while (std::abs(hi - lo) > tol) {
    const double mid = 0.5 * (lo + hi);
    (pred(mid) ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

size_t settle(const std::vector<double>& v, size_t k, double tol) {
  size_t a = k, b = k;
  while (a > 0 && std::abs(v[a - 1] - v[k]) <= tol) --a;
  while (b + 1 < v.size() && std::abs(v[b + 1] - v[k]) <= tol) ++b;
  return (a + b) / 2;
}

std::optional<std::pair<double, double>> flat_bottom_span(const std::vector<double>& x, const std::vector<double>& v,
                                                          size_t k, double rise) {
  const double level = v[k] + rise;
  std::optional<double> lo, hi;
  for (size_t i = k; i > 0 && !lo; --i)
    if (v[i - 1] >= level) lo = x[i - 1] + (level - v[i - 1]) / (v[i] - v[i - 1]) * (x[i] - x[i - 1]);
  for (size_t i = k; i + 1 < v.size() && !hi; ++i)
    if (v[i + 1] >= level) hi = x[i] + (level - v[i]) / (v[i + 1] - v[i]) * (x[i + 1] - x[i]);
  if (!lo || !hi) return std::nullopt;
  return std::make_pair(*lo, *hi);
}

std::optional<double> flat_bottom_middle(const std::vector<double>& x, const std::vector<double>& v, size_t k,
                                         double rise) {
  const auto span = flat_bottom_span(x, v, k, rise);
  if (!span) return std::nullopt;
  return 0.5 * (span->first + span->second);
}

LocalParabola local_parabola(const std::vector<double>& x, const std::vector<double>& v, double centre, double half,
                             bool biweight) {
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d atb = Eigen::Vector3d::Zero();
  LocalParabola p;
  for (size_t i = 0; i < x.size(); ++i) {
    const double t = x[i] - centre, u = t / half;
    if (biweight ? std::abs(u) >= 1 : std::abs(t) > half) continue;
    const double w = biweight ? (1 - u * u) * (1 - u * u) : 1.0;
    const Eigen::Vector3d row(t * t, t, 1);
    ata += w * row * row.transpose();
    atb += w * row * v[i];
    ++p.samples;
  }
  if (p.samples > 0) p.coef = ata.ldlt().solve(atb);
  return p;
}

std::optional<double> parabola_vertex(const std::vector<double>& x, const std::vector<double>& v, size_t k, double half,
                                      bool lowest) {
  const LocalParabola p = local_parabola(x, v, x[k], half, false);
  if (p.samples < 7) return std::nullopt;
  const Eigen::Vector3d& c = p.coef;
  if (!((lowest ? c(0) : -c(0)) > 1e-9)) return std::nullopt;
  const double t = -c(1) / (2 * c(0));
  if (!(std::abs(t) <= half)) return std::nullopt;
  return x[k] + t;
}

size_t arg_extreme(const std::vector<double>& v, bool largest) {
  return static_cast<size_t>((largest ? std::max_element(v.begin(), v.end()) : std::min_element(v.begin(), v.end())) -
                             v.begin());
}

Notch deepest_behind_chord(const std::vector<Eigen::Vector2d>& c, double half) {
  const Eigen::Vector2d a = c.front(), e = c.back();
  std::vector<double> ys, depth;
  for (const Eigen::Vector2d& q : c)
    ys.push_back(q.x()), depth.push_back(q.y() - (a.y() + (q.x() - a.x()) / (e.x() - a.x()) * (e.y() - a.y())));
  Notch n;
  n.k = arg_extreme(depth, false);
  n.depth = depth[n.k];
  n.vertex_y = parabola_vertex(ys, depth, n.k, half, true);
  n.ys = std::move(ys), n.depths = std::move(depth);
  return n;
}

std::pair<size_t, double> refined_corner(const std::vector<double>& x, const std::vector<double>& v, double v_end,
                                         double half) {
  const size_t n = x.size();
  Eigen::Vector2d end(x[n - 1], v[n - 1]);
  if ((v[n - 1] - v_end) * (v[n - 2] - v_end) < 0) {
    const double t = (v_end - v[n - 2]) / (v[n - 1] - v[n - 2]);
    end = {x[n - 2] + t * (x[n - 1] - x[n - 2]), v_end};
  }
  const Eigen::Vector2d a(x[0], v[0]), d = (end - a).normalized();
  std::vector<double> dist;
  for (size_t i = 0; i < n; ++i) dist.push_back(d.x() * (v[i] - a.y()) - d.y() * (x[i] - a.x()));
  const size_t k = arg_extreme(dist, true);
  return {k, settled_vertex(x, dist, k, half, false).value_or(x[k])};
}

std::vector<double> despiked(const std::vector<double>& v, size_t half, double tol) {
  std::vector<double> out(v), window;
  for (size_t i = 0; i < v.size(); ++i) {
    const size_t a = i > half ? i - half : 0, b = std::min(v.size() - 1, i + half);
    window.assign(v.begin() + static_cast<std::ptrdiff_t>(a), v.begin() + static_cast<std::ptrdiff_t>(b) + 1);
    std::nth_element(window.begin(), window.begin() + static_cast<std::ptrdiff_t>(window.size() / 2), window.end());
    if (const double m = window[window.size() / 2]; std::abs(v[i] - m) > tol) out[i] = m;
  }
  return out;
}

double minimum_centroid(const std::vector<double>& x, const std::vector<double>& v, size_t k, double depth) {
  const double level = v[k] + depth;
  size_t a = k, b = k;
  while (a > 0 && v[a - 1] < level) --a;
  while (b + 1 < v.size() && v[b + 1] < level) ++b;
  // Segments [i, i + 1] from the one rising out on the left to the one on the right.
  const size_t first = a > 0 ? a - 1 : 0, last = b + 1 < v.size() ? b + 1 : b;
  double area = 0, moment = 0;
  for (size_t i = first; i < last; ++i) {
    double x0 = x[i], x1 = x[i + 1], f0 = level - v[i], f1 = level - v[i + 1];
    // Clip the segment to where it lies under the level.
    if (f0 < 0) x0 = x0 + (x1 - x0) * (-f0) / (f1 - f0), f0 = 0;
    if (f1 < 0) x1 = x1 - (x1 - x0) * (-f1) / (f0 - f1), f1 = 0;
    const double dx = x1 - x0;
    area += 0.5 * (f0 + f1) * dx;
    moment += dx / 6 * (2 * x0 * f0 + x0 * f1 + x1 * f0 + 2 * x1 * f1);
  }
  return area != 0 ? moment / area : x[k];
}

std::optional<double> settled_vertex(const std::vector<double>& x, const std::vector<double>& v, size_t k, double half,
                                     bool lowest) {
  double c = x[k];
  for (int it = 0; it < 30; ++it) {
    const LocalParabola p = local_parabola(x, v, c, half, true);
    if (p.samples < 7) return std::nullopt;
    const Eigen::Vector3d& q = p.coef;
    if (!((lowest ? q(0) : -q(0)) > 1e-9)) return std::nullopt;
    const double step = std::clamp(-q(1) / (2 * q(0)), -0.5 * half, 0.5 * half);
    c += step;
    if (!(c >= std::min(x.front(), x.back()) && c <= std::max(x.front(), x.back()))) return std::nullopt;
    if (std::abs(step) < 1e-3) break;
  }
  return c;
}

std::optional<double> flat_top_vertex(const std::vector<double>& x, const std::vector<double>& v, double drop,
                                      double min_span) {
  if (x.size() != v.size() || x.empty()) return std::nullopt;
  std::vector<double> below = v;
  for (double& b : below) b = -b;
  const size_t k = arg_extreme(v, true);
  const auto span = flat_bottom_span(x, below, k, drop);
  if (!span || span->second - span->first <= min_span) return std::nullopt;
  const double mid = 0.5 * (span->first + span->second);
  size_t km = k;
  for (size_t i = 0; i < x.size(); ++i)
    if (std::abs(x[i] - mid) < std::abs(x[km] - mid)) km = i;
  return settled_vertex(x, v, km, 0.5 * (span->second - span->first), false);
}

}  // namespace bodyscan
