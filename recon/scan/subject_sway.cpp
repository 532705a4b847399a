#include "recon/scan/subject_sway.hpp"

#include <tbb/parallel_for.h>
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "recon/spatial/knn_index.hpp"

namespace bodyscan {
namespace {

// One point against another sweep's local surface. With the sway x (knot values),
// its height above that surface is r0 - n . (x(frame of the point) - sum_j c_j
// x(frame of point j)), the c_j being how much each of the surface's points weighs
// in its height there (they sum to 1); the frames enter through the knots' hat
// weights.
struct Pair {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double r0 = 0;                              // the distance as measured, mm
  double weight = 1;                          // confidence
  int fold = 0;                               // the block of space the anchor lies in, for cross-validation
  std::vector<std::pair<int, double>> knots;  // (knot, weight): +point, -plane
};

struct Knots {
  int first = 0, spacing = 1, count = 0;
  // Adds frame f's hat weights, times `scale`, to `out`.
  void add(int f, double scale, std::vector<std::pair<int, double>>& out) const {
    const double u = static_cast<double>(f - first) / spacing;
    const int k = std::clamp(static_cast<int>(std::floor(u)), 0, count - 1);
    const double a = std::clamp(u - k, 0.0, 1.0);
    out.emplace_back(k, scale * (1 - a));
    if (k + 1 < count && a > 0) out.emplace_back(k + 1, scale * a);
  }
};

void merge(std::vector<std::pair<int, double>>& v) {
  std::sort(v.begin(), v.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  size_t w = 0;
  for (size_t r = 0; r < v.size(); ++r) {
    if (w > 0 && v[w - 1].first == v[r].first)
      v[w - 1].second += v[r].second;
    else
      v[w++] = v[r];
  }
  v.resize(w);
}

double residual(const Pair& p, const std::vector<Eigen::Vector3d>& x) {
  double r = p.r0;
  for (const auto& [k, a] : p.knots) r -= a * p.normal.dot(x[static_cast<size_t>(k)]);
  return r;
}

// The pairs' weighted RMS distance at the sway x, each distance capped at `cap`.
double pair_rms(const std::vector<Pair>& pairs, const std::vector<Eigen::Vector3d>& x, double cap) {
  double ss = 0, sw = 0;
  for (const Pair& p : pairs) {
    const double r = std::min(std::abs(residual(p, x)), cap);
    ss += p.weight * r * r, sw += p.weight;
  }
  return sw > 0 ? std::sqrt(ss / sw) : 0;
}

// The median distance from a point to the nearest point of its laser's next or
// previous stripe (another frame of the same laser), over a sample of the anchors.
double stripe_spacing(const PointCloud& cloud, const KnnIndex& index, const std::vector<size_t>& anchors) {
  const size_t step = std::max<size_t>(1, anchors.size() / 2000);
  std::vector<double> found(anchors.size() / step + 1, -1);
  tbb::parallel_for(size_t{0}, found.size(), [&](size_t s) {
    if (s * step >= anchors.size()) return;
    const size_t i = anchors[s * step];
    for (const auto& [j, d2] : index.within_radius(cloud.positions[i], 40.f)) {
      if (cloud.laser[j] == cloud.laser[i] && cloud.frame[j] != cloud.frame[i] && cloud.frame[j] >= 0) {
        found[s] = std::sqrt(static_cast<double>(d2));
        return;  // nearest first
      }
    }
  });
  found.erase(std::remove(found.begin(), found.end(), -1.0), found.end());
  if (found.empty()) return 0;
  std::nth_element(found.begin(), found.begin() + static_cast<std::ptrdiff_t>(found.size() / 2), found.end());
  return found[found.size() / 2];
}

// The anchor i against the other sweep's points other[b, e): their surface near the
// anchor, a quadratic height field over their plane (where they span three stripes
// or more; else no pair), fitted with Gaussian weights towards the anchor (sigma a
// third of the radius). The anchor's height above it is the pair's distance; as
// each of their points enters that height linearly, so does its moment's sway.
bool local_height(const PointCloud& cloud, const std::vector<Vec3f>& moved, size_t i,
                  const std::vector<std::pair<int32_t, uint32_t>>& other, size_t b, size_t e, float radius,
                  const Knots& knots, const std::vector<Eigen::Vector3d>& x, Pair& p) {
  const bool has_conf = cloud.has_confidence();
  const Eigen::Vector3d at = moved[i].cast<double>();
  const double inv = 1 / (2 * std::pow(radius / 3.0, 2));
  const size_t m = e - b;
  std::vector<double> w(m);
  Eigen::Vector3d cm = Eigen::Vector3d::Zero();
  double sw = 0, conf = 0;
  for (size_t t = 0; t < m; ++t) {
    const uint32_t j = other[b + t].second;
    w[t] = std::exp(-(moved[j].cast<double>() - at).squaredNorm() * inv);
    cm += w[t] * moved[j].cast<double>();
    sw += w[t];
    conf += w[t] * (has_conf ? cloud.confidence[j] : 1.f);
  }
  cm /= sw;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (size_t t = 0; t < m; ++t) {
    const Eigen::Vector3d d = moved[other[b + t].second].cast<double>() - cm;
    cov += w[t] * d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov / sw);
  const Eigen::Vector3d ev = es.eigenvalues();
  // More than one stripe (the middle spread, against the radius, which scales with
  // the stripes' spacing), and a surface rather than a blob.
  if (ev[1] < 0.01 * radius * radius || ev[0] > 0.3 * ev[1]) return false;
  const Eigen::Vector3d n = es.eigenvectors().col(0), t1 = es.eigenvectors().col(2), t2 = es.eigenvectors().col(1);
  // Height field h(u, v) over the plane, u and v in radii.
  auto basis = [&](const Eigen::Vector3d& q) {
    const Eigen::Vector3d d = q - cm;
    const double u = t1.dot(d) / radius, v = t2.dot(d) / radius;
    Eigen::Matrix<double, 6, 1> f;
    f << 1, u, v, u * u, u * v, v * v;
    return f;
  };
  int frames_seen = 0;
  {
    int last = INT32_MIN;
    std::vector<int> fs;
    for (size_t t = 0; t < m; ++t) fs.push_back(cloud.frame[other[b + t].second]);
    std::sort(fs.begin(), fs.end());
    for (int f : fs) frames_seen += f != last, last = f;
  }
  // A plane through the stripes either side of the anchor lies inside a curved
  // surface, by the curvature times their spread; the pairs then read every sweep
  // as outside the others, and the path pushed opposite sweeps into each other (a
  // still body came out 0.1-0.2 mm thin, a leg's girth 1 mm small). A parabola
  // needs three stripes.
  if (frames_seen < 3) return false;
  Eigen::Matrix<double, 6, 6> mm = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> rhs = Eigen::Matrix<double, 6, 1>::Zero();
  for (size_t t = 0; t < m; ++t) {
    const Eigen::Vector3d q = moved[other[b + t].second].cast<double>();
    const auto f = basis(q);
    mm += w[t] * f * f.transpose();
    rhs += w[t] * f * n.dot(q - cm);
  }
  const Eigen::FullPivLU<Eigen::Matrix<double, 6, 6>> lu(mm);
  if (lu.rank() < 6 || lu.rcond() < 1e-6) return false;
  const Eigen::Matrix<double, 6, 1> z = lu.solve(basis(at));
  const double height = n.dot(at - cm) - z.dot(rhs);
  p.normal = n;
  p.knots.clear();
  knots.add(cloud.frame[i], 1, p.knots);
  for (size_t t = 0; t < m; ++t) {
    const Eigen::Vector3d q = moved[other[b + t].second].cast<double>();
    knots.add(cloud.frame[other[b + t].second], -w[t] * z.dot(basis(q)), p.knots);
  }
  merge(p.knots);
  // As measured (no sway undone): the height plus the sway the moved points carry.
  p.r0 = height;
  for (const auto& [k, c] : p.knots) p.r0 += c * n.dot(x[static_cast<size_t>(k)]);
  p.weight = conf / sw;
  return true;
}

// Which of the cross-validation folds a point's pairs go to: space cut into cubes
// of cv_block_mm, the cubes dealt out to the folds by a hash of their index (so a
// fold is skin spread over the whole body, and the skin next to a held-out cube is
// usually in another fold).
int fold_of(const Vec3f& p, const SwayOptions& o) {
  if (o.cv_folds < 2) return 0;
  const auto cell = [&](float v) { return static_cast<int64_t>(std::floor(v / o.cv_block_mm)); };
  uint64_t h = static_cast<uint64_t>(cell(p.x())) * 73856093ULL ^ static_cast<uint64_t>(cell(p.y())) * 19349663ULL ^
               static_cast<uint64_t>(cell(p.z())) * 83492791ULL;
  h ^= h >> 29, h *= 0xbf58476d1ce4e5b9ULL, h ^= h >> 32;
  return static_cast<int>(h % static_cast<uint64_t>(o.cv_folds));
}

// The pairs at the current sway: each anchor against the other sweeps' points among
// `candidates` (every point, or an even share of a dense cloud).
std::vector<Pair> find_pairs(const PointCloud& cloud, const std::vector<Vec3f>& moved,
                             const std::vector<size_t>& anchors, const std::vector<uint32_t>& candidates,
                             const Knots& knots, const SwayOptions& o, float radius,
                             const std::vector<Eigen::Vector3d>& x) {
  std::vector<Vec3f> at(candidates.size());
  for (size_t c = 0; c < candidates.size(); ++c) at[c] = moved[candidates[c]];
  const KnnIndex index(at);
  std::vector<std::vector<Pair>> found(anchors.size());
  const bool has_conf = cloud.has_confidence();
  tbb::parallel_for(size_t{0}, anchors.size(), [&](size_t a) {
    const size_t i = anchors[a];
    const int fi = cloud.frame[i];
    auto near = index.within_radius(moved[i], radius, false);  // sorted by laser and point below
    // Group the other moments' points by laser (one laser sweeps once, so its points
    // near here were seen at nearly one moment).
    std::vector<std::pair<int32_t, uint32_t>> other;
    for (const auto& [c, d2] : near) {
      const uint32_t j = candidates[c];
      const int fj = cloud.frame[j];
      if (fj < 0 || std::abs(fj - fi) < o.min_frame_gap) continue;
      other.emplace_back(cloud.laser[j], j);
    }
    std::sort(other.begin(), other.end());
    for (size_t b = 0; b < other.size();) {
      size_t e = b;
      while (e < other.size() && other[e].first == other[b].first) ++e;
      if (e - b >= o.min_group) {
        Pair p;
        if (local_height(cloud, moved, i, other, b, e, radius, knots, x, p)) {
          p.weight *= has_conf ? cloud.confidence[i] : 1.f;
          p.fold = fold_of(cloud.positions[i], o);
          if (p.weight > 0) found[a].push_back(std::move(p));
        }
      }
      b = e;
    }
  });
  std::vector<Pair> pairs;
  for (auto& f : found)
    for (Pair& p : f) pairs.push_back(std::move(p));
  return pairs;
}

// The normal equations of the pairs (one fold's, or all of them), and their
// weight: in all, and along each axis the path moves in.
struct System {
  Eigen::MatrixXd ata;
  Eigen::VectorXd atb;
  double total = 0;
  std::vector<double> axis;
  System(size_t unknowns, size_t dims)
      : ata(Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(unknowns), static_cast<Eigen::Index>(unknowns))),
        atb(Eigen::VectorXd::Zero(static_cast<Eigen::Index>(unknowns))),
        axis(dims, 0.0) {}
  void add(const System& o, double sign) {
    ata += sign * o.ata, atb += sign * o.atb, total += sign * o.total;
    for (size_t d = 0; d < axis.size(); ++d) axis[d] += sign * o.axis[d];
  }
};

// The path's slow part squared: B'B, B taking each of the m knots to its mean over
// the window of SwayOptions::slow_frames around it.
Eigen::MatrixXd slow_part(size_t m, const SwayOptions& o) {
  const int half = std::max(1, o.slow_frames / o.knot_frames / 2);
  Eigen::MatrixXd box = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(m), static_cast<Eigen::Index>(m));
  for (size_t k = 0; k < m; ++k) {
    const int b = std::max(0, static_cast<int>(k) - half),
              e = std::min(static_cast<int>(m) - 1, static_cast<int>(k) + half);
    for (int j = b; j <= e; ++j) box(static_cast<Eigen::Index>(k), j) = 1.0 / (e - b + 1);
  }
  return box.transpose() * box;
}

// The path that best explains the pairs under the smoothness, the mean-zero and the
// size terms of `reg` (`slow` is slow_part()).
StatusOr<std::vector<Eigen::Vector3d>> solve_path(const System& s, const SwayRegularization& reg, const SwayOptions& o,
                                                  size_t m, const std::vector<int>& axes, const Eigen::MatrixXd& slow) {
  const size_t dims = axes.size();
  if (reg.still) return std::vector<Eigen::Vector3d>(m, Eigen::Vector3d::Zero());
  Eigen::MatrixXd ata = s.ata;
  const double per_knot = s.total / static_cast<double>(m);
  for (size_t d = 0; d < dims; ++d) {
    // Per knot, the pairs' weight in all, or what they see along this axis.
    const double scale = reg.per_axis ? s.axis[d] / static_cast<double>(m) : per_knot;
    const double lambda = o.smoothness * scale;
    for (size_t k = 1; k + 1 < m; ++k) {
      const std::array<Eigen::Index, 3> idx = {static_cast<Eigen::Index>((k - 1) * dims + d),
                                               static_cast<Eigen::Index>(k * dims + d),
                                               static_cast<Eigen::Index>((k + 1) * dims + d)};
      const std::array<double, 3> c = {1, -2, 1};
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) ata(idx[a], idx[b]) += lambda * c[a] * c[b];
    }
    // Mean zero (the scan cannot tell where the body stands on average), and a
    // small weight on the sway itself, which holds the directions the pairs cannot
    // see (and knots nothing constrains) near zero instead of letting them drift.
    for (size_t a = 0; a < m; ++a) {
      for (size_t b = 0; b < m; ++b)
        ata(static_cast<Eigen::Index>(a * dims + d), static_cast<Eigen::Index>(b * dims + d)) +=
            per_knot / static_cast<double>(m);
      ata(static_cast<Eigen::Index>(a * dims + d), static_cast<Eigen::Index>(a * dims + d)) +=
          o.ridge * reg.ridge_scale * scale;
    }
    if (reg.slow_scale > 0) {
      for (size_t a = 0; a < m; ++a)
        for (size_t b = 0; b < m; ++b)
          ata(static_cast<Eigen::Index>(a * dims + d), static_cast<Eigen::Index>(b * dims + d)) +=
              o.ridge * reg.slow_scale * scale * slow(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
    }
  }
  const Eigen::VectorXd sol = ata.ldlt().solve(s.atb);
  if (!sol.allFinite()) return internal_error("sway: the path's least-squares system is singular");
  std::vector<Eigen::Vector3d> x(m, Eigen::Vector3d::Zero());
  for (size_t k = 0; k < m; ++k)
    for (size_t d = 0; d < dims; ++d) x[k][axes[d]] = sol[static_cast<Eigen::Index>(k * dims + d)];
  return x;
}

}  // namespace

Eigen::Vector3d SwayEstimate::at(double frame) const {
  if (knots.empty()) return Eigen::Vector3d::Zero();
  const double u = (frame - first_frame) / knot_frames;
  if (u <= 0) return knots.front();
  const size_t k = static_cast<size_t>(std::floor(u));
  if (k + 1 >= knots.size()) return knots.back();
  const double a = u - static_cast<double>(k);
  return (1 - a) * knots[k] + a * knots[k + 1];
}

StatusOr<SwayEstimate> estimate_sway(const PointCloud& cloud, const SwayOptions& o) {
  const size_t n = cloud.size();
  if (cloud.frame.size() != n || cloud.laser.size() != n)
    return invalid_argument("sway: the cloud needs each point's frame and laser");
  if (o.knot_frames < 1 || o.radius_mm <= 0 || o.min_frame_gap < 1 || o.iterations < 1 || !(o.converged_mm >= 0) ||
      o.min_group < 3)
    return invalid_argument("sway: bad options");
  if (o.regularizations.empty() || (o.cv_folds >= 2 && !(o.cv_block_mm > 0)) || o.slow_frames < 1)
    return invalid_argument("sway: bad options (no hold to try, or no cubes to fold by)");
  for (const SwayRegularization& r : o.regularizations)
    if (!(r.ridge_scale >= 0) || !(r.slow_scale >= 0)) return invalid_argument("sway: a hold's weights must be >= 0");
  if (std::all_of(o.regularizations.begin(), o.regularizations.end(),
                  [](const SwayRegularization& r) { return r.still; }))
    return invalid_argument("sway: every hold stands still; offer one that moves");
  SwayEstimate est;
  est.knot_frames = o.knot_frames;
  int fmin = INT32_MAX, fmax = INT32_MIN;
  for (int32_t f : cloud.frame)
    if (f >= 0) fmin = std::min(fmin, f), fmax = std::max(fmax, f);
  if (fmin > fmax || fmax - fmin < o.min_frame_gap) {
    est.not_estimated = "the scan's points were all seen within " + std::to_string(o.min_frame_gap) + " frames";
    return est;
  }
  Knots knots{fmin, o.knot_frames, (fmax - fmin) / o.knot_frames + 2};
  est.first_frame = fmin;
  const size_t m = static_cast<size_t>(knots.count);
  std::vector<int> axes = o.vertical ? std::vector<int>{0, 1, 2} : std::vector<int>{0, 2};
  const size_t dims = axes.size(), unknowns = m * dims;
  const Eigen::MatrixXd slow = slow_part(m, o);

  std::vector<size_t> anchors;
  const size_t stride = std::max<size_t>(1, (n + o.max_anchors - 1) / std::max<size_t>(1, o.max_anchors));
  for (size_t i = 0; i < n; i += stride)
    if (cloud.frame[i] >= 0) anchors.push_back(i);

  {
    const KnnIndex index(cloud.positions);
    est.stripe_spacing_mm = stripe_spacing(cloud, index, anchors);
  }
  if (est.stripe_spacing_mm > o.max_stripe_spacing_mm) {
    char why[160];
    std::snprintf(why, sizeof why, "the stripes are %.0f mm apart, more than %.0f: scan more steps",
                  est.stripe_spacing_mm, o.max_stripe_spacing_mm);
    est.not_estimated = why;
    return est;
  }
  if (est.stripe_spacing_mm <= 0) {
    est.not_estimated = "no laser's stripes lie side by side";
    return est;
  }
  est.radius_mm = std::max<double>(o.radius_mm, 2.5 * est.stripe_spacing_mm);
  const float radius = static_cast<float>(est.radius_mm);

  std::vector<Eigen::Vector3d> x(m, Eigen::Vector3d::Zero());
  std::vector<uint32_t> candidates;
  const size_t every = std::max<size_t>(1, (n + o.max_candidates - 1) / std::max<size_t>(1, o.max_candidates));
  for (size_t i = 0; i < n; i += every)
    if (cloud.frame[i] >= 0) candidates.push_back(static_cast<uint32_t>(i));
  std::vector<Vec3f> moved = cloud.positions;
  std::vector<Pair> pairs;
  for (int it = 0; it < o.iterations; ++it) {
    pairs = find_pairs(cloud, moved, anchors, candidates, knots, o, radius, x);
    if (it == 0) est.rms_before_mm = pair_rms(pairs, x, o.max_residual_mm);  // x is zero: as measured
    if (pairs.empty()) break;
    // Robust weights at the current sway; then the normal equations, fold by fold.
    const size_t folds = o.cv_folds >= 2 ? static_cast<size_t>(o.cv_folds) : 1;
    std::vector<System> sys(folds, System(unknowns, dims));
    std::vector<double> weight(pairs.size(), 0.0);
    std::vector<std::pair<Eigen::Index, double>> row;
    for (size_t q = 0; q < pairs.size(); ++q) {
      const Pair& p = pairs[q];
      const double r = std::abs(residual(p, x));
      if (r > o.max_residual_mm) continue;
      const double w = p.weight * (r <= o.huber_mm ? 1.0 : o.huber_mm / r);
      weight[q] = w;
      System& f = sys[folds > 1 ? static_cast<size_t>(p.fold) : 0];
      f.total += w;
      for (size_t d = 0; d < dims; ++d) f.axis[d] += w * p.normal[axes[d]] * p.normal[axes[d]];
      row.clear();
      for (const auto& [k, a] : p.knots)
        for (size_t d = 0; d < dims; ++d)
          row.emplace_back(static_cast<Eigen::Index>(static_cast<size_t>(k) * dims + d), a * p.normal[axes[d]]);
      for (const auto& [ri, rv] : row) {
        f.atb[ri] += w * rv * p.r0;
        for (const auto& [ci, cv] : row) f.ata(ri, ci) += w * rv * cv;
      }
    }
    System all(unknowns, dims);
    for (const System& f : sys) all.add(f, 1);
    if (all.total <= 0) break;
    // Which of the regularisations explains the pairs of skin it was not fitted
    // to best (when there is a choice).
    // Without a choice by held-out skin the first moving hold is taken: a body is
    // never taken to stand still unless the skin says so.
    SwayRegularization chosen = o.regularizations.front();
    for (const SwayRegularization& r : o.regularizations)
      if (!r.still) {
        chosen = r;
        break;
      }
    if (folds > 1 && o.regularizations.size() > 1) {
      // Each candidate's mean squared distance over each fold's pairs, with the
      // path fitted to the other folds.
      std::vector<std::vector<size_t>> in_fold(folds);
      for (size_t q = 0; q < pairs.size(); ++q)
        if (weight[q] > 0) in_fold[static_cast<size_t>(pairs[q].fold)].push_back(q);
      std::vector<std::vector<double>> err(o.regularizations.size(), std::vector<double>(folds, 0.0));
      // Standing still is offered at the first pairing only, made at no sway: once
      // a path moved the sweeps, their pairs no longer weigh the two fairly.
      const auto offered = [&](size_t c) { return !(o.regularizations[c].still && it > 0); };
      for (size_t f = 0; f < folds; ++f) {
        System train = all;
        train.add(sys[f], -1);
        if (train.total <= 0 || sys[f].total <= 0) continue;
        for (size_t c = 0; c < o.regularizations.size(); ++c) {
          if (!offered(c)) continue;
          auto fit = solve_path(train, o.regularizations[c], o, m, axes, slow);
          if (!fit.ok()) return fit.status();
          for (size_t q : in_fold[f]) {
            const double r = residual(pairs[q], *fit);
            err[c][f] += weight[q] * r * r / sys[f].total;
          }
        }
      }
      // The lowest mean error; then, the candidates being listed from the strongest
      // hold to the weakest, the first whose excess over it is within one standard
      // error of the folds' differences (a weaker hold must earn its place).
      const auto mean = [&](const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / folds; };
      size_t best = 0;
      while (!offered(best)) ++best;
      for (size_t c = best + 1; c < err.size(); ++c)
        if (offered(c) && mean(err[c]) < mean(err[best])) best = c;
      size_t take = best;
      for (size_t c = 0; c < best; ++c) {
        if (!offered(c)) continue;
        std::vector<double> d(folds);
        for (size_t f = 0; f < folds; ++f) d[f] = err[c][f] - err[best][f];
        const double md = mean(d);
        double var = 0;
        for (double v : d) var += (v - md) * (v - md);
        const double se = std::sqrt(var / static_cast<double>(folds - 1) / static_cast<double>(folds));
        if (md <= se) {
          take = c;
          break;
        }
      }
      chosen = o.regularizations[take];
      // A hold not offered this time keeps the figure it had when it was.
      est.held_out_rms_mm.resize(err.size(), 0.0);
      for (size_t c = 0; c < err.size(); ++c)
        if (offered(c)) est.held_out_rms_mm[c] = std::sqrt(mean(err[c]));
    }
    est.regularization = chosen;
    auto fit = solve_path(all, chosen, o, m, axes, slow);
    if (!fit.ok()) return fit.status();
    double moved_most = 0;
    for (size_t k = 0; k < m; ++k) moved_most = std::max(moved_most, ((*fit)[k] - x[k]).norm());
    x = std::move(*fit);
    est.iterations = it + 1;
    est.last_move_mm = moved_most;
    est.knots = x;
    tbb::parallel_for(size_t{0}, n, [&](size_t i) {
      moved[i] = cloud.frame[i] >= 0 ? (cloud.positions[i].cast<double>() - est.at(cloud.frame[i])).cast<float>()
                                     : cloud.positions[i];
    });
    if (moved_most <= o.converged_mm) break;
  }
  est.pairs = pairs.size();
  if (pairs.empty()) {
    est.knots.clear();
    est.not_estimated = "no two sweeps saw the same skin";
    return est;
  }
  est.knots = x;
  est.rms_after_mm = pair_rms(pairs, x, o.max_residual_mm);
  for (const Eigen::Vector3d& k : x) est.peak_mm = std::max(est.peak_mm, k.norm());
  return est;
}

void undo_sway(PointCloud& cloud, const SwayEstimate& sway) {
  if (sway.empty() || cloud.frame.size() != cloud.size()) return;
  for (size_t i = 0; i < cloud.size(); ++i)
    if (cloud.frame[i] >= 0)
      cloud.positions[i] = (cloud.positions[i].cast<double>() - sway.at(cloud.frame[i])).cast<float>();
}

}  // namespace bodyscan
