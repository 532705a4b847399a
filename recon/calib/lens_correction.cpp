#include "recon/calib/lens_correction.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <numeric>
#include <optional>

#include <string>
#include <tuple>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include "recon/calib/components.hpp"

#include "recon/calib/plane_projection.hpp"  // fit_homography

namespace bodyscan {

using Eigen::Vector2d;

namespace {

// ---- Dots -------------------------------------------------------------------

// The value below which `fraction` of the pixels lie (of every fourth row: plenty
// for a level that only sets a floor).
int percentile(const ImageView& image, double fraction) {
  std::vector<uint32_t> hist(65536, 0);
  size_t counted = 0;
  for (int y = 0; y < image.height; y += 4, counted += image.width)
    for (int x = 0; x < image.width; ++x) ++hist[image.row(y)[x]];
  const double target = fraction * static_cast<double>(counted);
  double below = 0;
  for (int v = 0; v < 65536; ++v) {
    below += hist[v];
    if (below >= target) return v;
  }
  return 65535;
}

// ---- Grid -------------------------------------------------------------------

// Points sorted into square cells, for "the nearest point within r of q".
class Buckets {
 public:
  Buckets(const std::vector<Vector2d>& p, double cell) : p_(p) {
    Vector2d hi = lo_ = p.front();
    for (const Vector2d& q : p) lo_ = lo_.cwiseMin(q), hi = hi.cwiseMax(q);
    // Stray blobs a pixel apart must not make the table huge.
    cell_ = std::max(cell, (hi - lo_).maxCoeff() / 1024);
    nx_ = static_cast<int>((hi.x() - lo_.x()) / cell_) + 1;
    ny_ = static_cast<int>((hi.y() - lo_.y()) / cell_) + 1;
    cells_.resize(static_cast<size_t>(nx_) * ny_);
    for (size_t i = 0; i < p.size(); ++i) {
      const auto [cx, cy] = cell_of(p[i]);
      cells_[static_cast<size_t>(cy) * nx_ + cx].push_back(static_cast<int>(i));
    }
  }

  // The point nearest q within `radius` (at most one cell), or -1.
  int nearest(const Vector2d& q, double radius) const {
    radius = std::min(radius, cell_);
    const auto [cx, cy] = cell_of(q);
    int best = -1;
    double best_d2 = radius * radius;
    for (int y = std::max(cy - 1, 0); y <= std::min(cy + 1, ny_ - 1); ++y)
      for (int x = std::max(cx - 1, 0); x <= std::min(cx + 1, nx_ - 1); ++x)
        for (int i : cells_[static_cast<size_t>(y) * nx_ + x]) {
          const double d2 = (p_[i] - q).squaredNorm();
          if (d2 < best_d2) best = i, best_d2 = d2;
        }
    return best;
  }

 private:
  std::pair<int, int> cell_of(const Vector2d& q) const {
    // Clamped into a range one cell wider than the table, so neighbours of outside
    // points are still looked at while far-off ones land on no cell.
    const double fx = std::floor((q.x() - lo_.x()) / cell_), fy = std::floor((q.y() - lo_.y()) / cell_);
    return {static_cast<int>(std::clamp(fx, -2.0, nx_ + 1.0)), static_cast<int>(std::clamp(fy, -2.0, ny_ + 1.0))};
  }

  const std::vector<Vector2d>& p_;
  Vector2d lo_;
  double cell_ = 1;
  int nx_ = 0, ny_ = 0;
  std::vector<std::vector<int>> cells_;
};

int64_t place_key(int col, int row) { return (static_cast<int64_t>(col) << 32) | static_cast<uint32_t>(row); }

// ---- Splines and tables -----------------------------------------------------

double kernel(double r2) { return r2 > 0 ? r2 * std::log(r2) : 0.0; }

// The monomials x^i y^j, i + j <= degree, at q.
Eigen::VectorXd monomials(const Vector2d& q, int degree) {
  Eigen::VectorXd m((degree + 1) * (degree + 2) / 2);
  int k = 0;
  for (int d = 0; d <= degree; ++d)
    for (int j = 0; j <= d; ++j) m(k++) = std::pow(q.x(), d - j) * std::pow(q.y(), j);
  return m;
}

// Two thin-plate splines on the same sites, one per output coordinate (thesis fig.
// 3.1): f(p) = poly(p) + sum_i F_i r_i^2 ln r_i^2, with sum_i F_i q(p_i) = 0 for every
// monomial q of the polynomial part. The thesis's polynomial is affine; a cubic one
// takes in the bulk of a lens's distortion, leaving the kernels only the remainder,
// which they interpolate more closely between dots. The sites are scaled to unit RMS
// radius so the system is well conditioned; the spline does not depend on the scale
// (the side conditions cancel the r^2 term a scale adds), only the smoothing's
// meaning does.
class PlateSpline {
 public:
  static std::optional<PlateSpline> fit(const std::vector<Vector2d>& from, const std::vector<Vector2d>& to,
                                        double smoothing, int degree) {
    const Eigen::Index n = static_cast<Eigen::Index>(from.size());
    PlateSpline s;
    s.degree_ = degree;
    s.centre_ = Vector2d::Zero();
    for (const Vector2d& p : from) s.centre_ += p;
    s.centre_ /= static_cast<double>(n);
    double r2 = 0;
    for (const Vector2d& p : from) r2 += (p - s.centre_).squaredNorm();
    s.scale_ = r2 > 0 ? 1 / std::sqrt(r2 / static_cast<double>(n)) : 1.0;
    std::vector<Vector2d> sites(from.size());
    for (Eigen::Index i = 0; i < n; ++i) sites[i] = (from[i] - s.centre_) * s.scale_;
    const Eigen::Index m = (degree + 1) * (degree + 2) / 2;
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n + m, n + m);
    Eigen::MatrixXd b = Eigen::MatrixXd::Zero(n + m, 2);
    for (Eigen::Index i = 0; i < n; ++i) {
      for (Eigen::Index j = 0; j < i; ++j) a(i, j) = a(j, i) = kernel((sites[i] - sites[j]).squaredNorm());
      a(i, i) = smoothing;
      const Eigen::VectorXd q = monomials(sites[i], degree);
      a.block(i, n, 1, m) = q.transpose();
      a.block(n, i, m, 1) = q;
      b.row(i) = to[i].transpose();
    }
    const Eigen::MatrixXd x = a.partialPivLu().solve(b);
    if (!x.allFinite()) return std::nullopt;
    s.poly_ = x.bottomRows(m);
    s.kernel_terms_.resize(static_cast<size_t>(n));
    for (Eigen::Index i = 0; i < n; ++i) s.kernel_terms_[i] = {sites[i].x(), sites[i].y(), x(i, 0), x(i, 1)};
    return s;
  }

  Vector2d operator()(const Vector2d& p) const {
    const Vector2d q = (p - centre_) * scale_;
    const Vector2d poly = poly_.transpose() * monomials(q, degree_);
    // The kernels' sum in plain scalars: the lens tables evaluate it for every cell
    // over every site, and a build that does not inline Eigen (the sanitizers')
    // would spend most of a calibration on its temporaries.
    double fx = poly.x(), fy = poly.y();
    const double qx = q.x(), qy = q.y();
    for (const KernelTerm& t : kernel_terms_) {
      const double dx = qx - t.x, dy = qy - t.y;
      const double k = kernel(dx * dx + dy * dy);
      fx += k * t.wx;
      fy += k * t.wy;
    }
    return {fx, fy};
  }

 private:
  int degree_ = 1;
  Vector2d centre_;
  double scale_ = 1;
  Eigen::Matrix<double, Eigen::Dynamic, 2> poly_;
  struct KernelTerm {
    double x, y, wx, wy;  // a site (scaled) and its kernel's two weights
  };
  std::vector<KernelTerm> kernel_terms_;
};

// Forced inline: correct() calls it twice a point, and GCC at -O2 would not (a
// third of correct()'s time).
[[gnu::always_inline]] inline void catmull_rom(double t, double w[4]) {
  const double t2 = t * t, t3 = t2 * t;
  w[0] = 0.5 * (-t3 + 2 * t2 - t);
  w[1] = 0.5 * (3 * t3 - 5 * t2 + 2);
  w[2] = 0.5 * (-3 * t3 + 4 * t2 + t);
  w[3] = 0.5 * (t3 - t2);
}

// A 2-D field sampled every `step` pixels, interpolated by Catmull-Rom splines (exact
// for quadratics; the error of a smooth field falls as step^3).
class Table {
 public:
  Table() = default;
  // Covers [lo, hi]: one node more on each side for the interpolation's support.
  template <typename Field>
  Table(const Field& f, const Vector2d& lo, const Vector2d& hi, double step) : inverse_step_(1 / step) {
    origin_ = lo - Vector2d::Constant(step);
    nx_ = static_cast<int>(std::ceil((hi.x() - lo.x()) / step)) + 4;
    ny_ = static_cast<int>(std::ceil((hi.y() - lo.y()) / step)) + 4;
    v_.resize(static_cast<size_t>(nx_) * ny_);
    tbb::parallel_for(0, ny_, [&](int j) {
      for (int i = 0; i < nx_; ++i) v_[static_cast<size_t>(j) * nx_ + i] = f(origin_ + step * Vector2d(i, j));
    });
  }

  // False outside the covered area.
  bool at(const Vector2d& p, Vector2d& out) const {
    const double u = (p.x() - origin_.x()) * inverse_step_, v = (p.y() - origin_.y()) * inverse_step_;
    if (!(u >= 1 && v >= 1 && u < nx_ - 2 && v < ny_ - 2)) return false;
    const int i = static_cast<int>(u), j = static_cast<int>(v);
    double wx[4], wy[4];
    catmull_rom(u - i, wx);
    catmull_rom(v - j, wy);
    const Vector2d* row = &v_[static_cast<size_t>(j - 1) * nx_ + i - 1];
    Vector2d sum = Vector2d::Zero();
    for (int b = 0; b < 4; ++b, row += nx_) {
      sum.noalias() += wy[b] * (wx[0] * row[0] + wx[1] * row[1] + wx[2] * row[2] + wx[3] * row[3]);
    }
    out = sum;
    return true;
  }

  // The bounding box of the tabulated values.
  std::pair<Vector2d, Vector2d> value_range() const {
    Vector2d lo = v_.front(), hi = v_.front();
    for (const Vector2d& q : v_) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
    return {lo, hi};
  }

 private:
  Vector2d origin_ = Vector2d::Zero();
  double inverse_step_ = 1;
  int nx_ = 0, ny_ = 0;
  std::vector<Vector2d> v_;
};

// One output pixel of remap(): the top-left of its four source pixels (-1: none)
// and the bilinear fractions in 1/32768ths.
struct RemapEntry {
  int32_t offset = -1;
  uint16_t fx = 0, fy = 0;
};

double rms(const std::vector<Vector2d>& a, const std::vector<Vector2d>& b) {
  double ss = 0;
  for (size_t i = 0; i < a.size(); ++i) ss += (a[i] - b[i]).squaredNorm();
  return std::sqrt(ss / static_cast<double>(a.size()));
}

}  // namespace

// ---- find_dots ------------------------------------------------------------------

StatusOr<std::vector<Dot>> find_dots(const ImageView& image, const DotOptions& o) {
  if (!image.pixels || image.width <= 0 || image.height <= 0) return invalid_argument("dot grid: the image is empty");
  if (o.window < 3 || o.window > 255 || o.window % 2 == 0 || !(o.contrast > 0 && o.contrast < 1) || o.min_area < 1 ||
      o.max_area < 0 || !(o.max_elongation >= 1)) {
    return invalid_argument(
        "dot grid: the window must be odd and 3..255 pixels, the contrast in (0, 1), min_area >= 1, max_area >= 0 and "
        "max_elongation >= 1");
  }
  const int w = image.width, h = image.height, half = o.window / 2;
  // In dim parts (the room beside the board) a fraction of the local mean is a few
  // grey levels, which noise crosses: there a dot must be darker by a fraction of the
  // board's white.
  const double dim = 0.25 * percentile(image, 0.95);
  // The local mean by running sums: down each column over the window's rows, then
  // along the row. Each block of rows starts its column sums afresh.
  std::vector<uint8_t> dark(static_cast<size_t>(w) * h);
  tbb::parallel_for(tbb::blocked_range<int>(0, h, 64), [&](const tbb::blocked_range<int>& rows) {
    std::vector<uint32_t> column(w, 0);
    int y0 = std::max(rows.begin() - half, 0), y1 = y0;  // the rows summed: [y0, y1)
    for (int y = rows.begin(); y < rows.end(); ++y) {
      for (; y1 < std::min(y + half + 1, h); ++y1)
        for (int x = 0; x < w; ++x) column[x] += image.row(y1)[x];
      for (; y0 < y - half; ++y0)
        for (int x = 0; x < w; ++x) column[x] -= image.row(y0)[x];
      const uint16_t* in = image.row(y);
      uint8_t* out = &dark[static_cast<size_t>(y) * w];
      uint32_t sum = 0;
      for (int x = 0; x < std::min(half, w); ++x) sum += column[x];
      for (int x = 0; x < w; ++x) {
        if (x + half < w) sum += column[x + half];
        if (x > half) sum -= column[x - half - 1];
        const double area = (std::min(x + half + 1, w) - std::max(x - half, 0)) * (y1 - y0);
        // mean - value > contrast * max(mean, dim), times the window's area.
        out[x] = sum - in[x] * area > o.contrast * std::max<double>(sum, dim * area);
      }
    }
  });

  int count = 0;
  const std::vector<int> label = label_components(
      w, h, [&](int x, int y) { return dark[static_cast<size_t>(y) * w + x] != 0; }, &count);
  struct Blob {
    int area = 0, x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
    double sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
  };
  std::vector<Blob> blobs(static_cast<size_t>(count));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int l = label[static_cast<size_t>(y) * w + x];
      if (l < 0) continue;
      Blob& b = blobs[static_cast<size_t>(l)];
      ++b.area;
      b.x0 = std::min(b.x0, x), b.x1 = std::max(b.x1, x), b.y0 = std::min(b.y0, y), b.y1 = std::max(b.y1, y);
      b.sx += x, b.sy += y, b.sxx += double(x) * x, b.sxy += double(x) * y, b.syy += double(y) * y;
    }

  // The centroid takes in the dot's anti-aliased rim, which the threshold cuts
  // through: the blob's box grown by kRim pixels. Around that, a ring kRing wide
  // gives the background. Blobs whose ring leaves the image are cut by the border
  // or too near it to tell.
  constexpr int kRim = 2, kRing = 4;
  const int max_area = o.max_area > 0 ? o.max_area : o.window * o.window / 2;
  std::vector<Dot> dots;
  for (size_t l = 0; l < blobs.size(); ++l) {
    const Blob& b = blobs[l];
    if (b.area < o.min_area || b.area > max_area) continue;
    const int x0 = b.x0 - kRim, y0 = b.y0 - kRim, x1 = b.x1 + kRim, y1 = b.y1 + kRim;
    if (x0 - kRing < 0 || y0 - kRing < 0 || x1 + kRing >= w || y1 + kRing >= h) continue;
    const double mx = b.sx / b.area, my = b.sy / b.area;
    const double cxx = b.sxx / b.area - mx * mx, cxy = b.sxy / b.area - mx * my, cyy = b.syy / b.area - my * my;
    const double mid = 0.5 * (cxx + cyy), spread = std::sqrt(0.25 * (cxx - cyy) * (cxx - cyy) + cxy * cxy);
    if (!(mid - spread > 0) || (mid + spread) > o.max_elongation * o.max_elongation * (mid - spread)) continue;
    // The background: a plane fitted to the ring's pixels that are not dots, so it
    // follows uneven lighting across the dot.
    Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    for (int y = y0 - kRing; y <= y1 + kRing; ++y)
      for (int x = x0 - kRing; x <= x1 + kRing; ++x) {
        if ((x >= x0 && x <= x1 && y >= y0 && y <= y1) || dark[static_cast<size_t>(y) * w + x]) continue;
        const Eigen::Vector3d f(1, x - mx, y - my);
        normal += f * f.transpose();
        rhs += f * static_cast<double>(image.row(y)[x]);
      }
    if (!(normal(0, 0) >= 12)) continue;  // a ring of other blobs: too crowded to measure
    const Eigen::Vector3d plane = normal.ldlt().solve(rhs);
    double mass = 0;
    Vector2d moment = Vector2d::Zero();
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const int other = label[static_cast<size_t>(y) * w + x];
        if (other >= 0 && other != static_cast<int>(l)) continue;
        const double darkness = plane(0) + plane(1) * (x - mx) + plane(2) * (y - my) - image.row(y)[x];
        if (darkness <= 0) continue;
        mass += darkness;
        moment += darkness * Vector2d(x, y);
      }
    if (mass > 0) dots.push_back({moment / mass, b.area, mass});
  }
  return dots;
}

// ---- index_grid -----------------------------------------------------------------

std::vector<GridDot> index_grid(const std::vector<Dot>& dots, const GridOptions& o) {
  const int n = static_cast<int>(dots.size());
  if (n < 5) return {};
  std::vector<Vector2d> p(n);
  for (int i = 0; i < n; ++i) p[i] = dots[i].centre;
  std::vector<double> xs(n), ys(n);
  for (int i = 0; i < n; ++i) xs[i] = p[i].x(), ys[i] = p[i].y();
  std::nth_element(xs.begin(), xs.begin() + n / 2, xs.end());
  std::nth_element(ys.begin(), ys.begin() + n / 2, ys.end());
  const Vector2d middle(xs[n / 2], ys[n / 2]);
  std::vector<int> by_distance(n);
  std::iota(by_distance.begin(), by_distance.end(), 0);
  std::sort(by_distance.begin(), by_distance.end(),
            [&](int a, int b) { return (p[a] - middle).squaredNorm() < (p[b] - middle).squaredNorm(); });

  // The spacing and the grid's directions come from the central dots, where the
  // distortion is mildest: each one's four nearest neighbours are its grid
  // neighbours (diagonal ones are sqrt(2) farther), and their directions, taken
  // modulo 90 degrees (angles times 4), average to the grid's turn.
  const int central = std::min(n, 100);
  std::vector<double> nearest;
  std::vector<Vector2d> offsets;
  for (int c = 0; c < central; ++c) {
    const int i = by_distance[c];
    std::vector<std::pair<double, int>> d;
    d.reserve(n - 1);
    for (int j = 0; j < n; ++j)
      if (j != i) d.emplace_back((p[j] - p[i]).squaredNorm(), j);
    const int k = std::min(4, n - 1);
    std::partial_sort(d.begin(), d.begin() + k, d.end());
    nearest.push_back(std::sqrt(d[0].first));
    for (int m = 0; m < k; ++m) offsets.push_back(p[d[m].second] - p[i]);
  }
  std::nth_element(nearest.begin(), nearest.begin() + nearest.size() / 2, nearest.end());
  const double spacing = nearest[nearest.size() / 2];
  if (!(spacing > 0)) return {};
  double c4 = 0, s4 = 0;
  for (const Vector2d& d : offsets) {
    const double len = d.norm();
    if (len < 0.6 * spacing || len > 1.4 * spacing) continue;
    const double a = 4 * std::atan2(d.y(), d.x());
    c4 += std::cos(a), s4 += std::sin(a);
  }
  // In (-45, 45] degrees, so the first step points along +x as nearly as it can and
  // the second (turned +90 degrees, image y down) along +y.
  const double turn = std::atan2(s4, c4) / 4;
  const Vector2d step1 = spacing * Vector2d(std::cos(turn), std::sin(turn)),
                 step2 = spacing * Vector2d(-std::sin(turn), std::cos(turn));
  const Buckets buckets(p, spacing);

  struct Place {
    int dot, col, row;
    Vector2d step1, step2;  // the local grid steps when the place was found
  };
  auto grow = [&](int seed) {
    std::unordered_map<int64_t, Place> places;
    std::vector<int64_t> place_of(n, 0);
    std::vector<bool> placed(n, false);
    std::unordered_set<int64_t> conflicts;
    auto good = [&](int col, int row) -> const Place* {
      const int64_t k = place_key(col, row);
      const auto it = places.find(k);
      return it == places.end() || conflicts.count(k) ? nullptr : &it->second;
    };
    // The steps at a place: from its found neighbours on each axis (both sides
    // averaged), else those it was found with.
    auto local_steps = [&](const Place& q) {
      std::pair<Vector2d, Vector2d> s{q.step1, q.step2};
      for (int axis = 0; axis < 2; ++axis) {
        Vector2d sum = Vector2d::Zero();
        int k = 0;
        for (int sign : {-1, 1}) {
          const Place* nb = good(q.col + (axis == 0 ? sign : 0), q.row + (axis == 1 ? sign : 0));
          if (nb) sum += sign * (p[nb->dot] - p[q.dot]), ++k;
        }
        if (k > 0) (axis == 0 ? s.first : s.second) = sum / k;
      }
      return s;
    };
    std::deque<int64_t> queue;
    places[place_key(0, 0)] = {seed, 0, 0, step1, step2};
    place_of[seed] = place_key(0, 0);
    placed[seed] = true;
    queue.push_back(place_key(0, 0));
    while (!queue.empty()) {
      const int64_t key = queue.front();
      queue.pop_front();
      if (conflicts.count(key)) continue;
      const Place q = places.at(key);
      const auto [s1, s2] = local_steps(q);
      const std::array<std::tuple<int, int, Vector2d>, 4> moves = {
          {{1, 0, s1}, {-1, 0, Vector2d(-s1)}, {0, 1, s2}, {0, -1, Vector2d(-s2)}}};
      for (const auto& [dc, dr, s] : moves) {
        const int j = buckets.nearest(p[q.dot] + s, o.tolerance * s.norm());
        if (j < 0) continue;
        const int64_t k = place_key(q.col + dc, q.row + dr);
        const auto it = places.find(k);
        if (it != places.end()) {
          if (it->second.dot != j) {
            conflicts.insert(k);
            if (placed[j]) conflicts.insert(place_of[j]);
          }
          continue;
        }
        if (placed[j]) {
          conflicts.insert(place_of[j]);
          continue;
        }
        places[k] = {j, q.col + dc, q.row + dr, s1, s2};
        place_of[j] = k;
        placed[j] = true;
        queue.push_back(k);
      }
    }
    std::vector<GridDot> out;
    for (const auto& [k, q] : places)
      if (!conflicts.count(k)) out.push_back({p[q.dot], q.col, q.row});
    std::sort(out.begin(), out.end(),
              [](const GridDot& a, const GridDot& b) { return std::tie(a.row, a.col) < std::tie(b.row, b.col); });
    return out;
  };

  // A stray blob as the seed grows nothing: try the next dots out from the middle.
  std::vector<GridDot> best;
  for (int s = 0; s < std::min(n, 5) && 2 * best.size() < static_cast<size_t>(n); ++s) {
    std::vector<GridDot> g = grow(by_distance[s]);
    if (g.size() > best.size()) best = std::move(g);
  }
  return best;
}

// ---- LensCorrection -------------------------------------------------------------

struct LensCorrection::State {
  std::vector<GridDot> dots;  // what the splines were fitted to
  LensOptions options;
  PlateSpline forward, inverse;  // captured -> ideal, ideal -> captured
  Table forward_table, inverse_table;
  std::vector<RemapEntry> remap;  // per output pixel
};

StatusOr<LensCorrection> LensCorrection::fit(const std::vector<GridDot>& dots, int width, int height,
                                             const LensOptions& o) {
  if (width < 2 || height < 2) return invalid_argument("lens correction: the image must be at least 2 x 2 pixels");
  // Each fold must still pin the polynomial part down: twice its terms at least.
  const int terms = (o.degree + 1) * (o.degree + 2) / 2;
  if (!(o.centre_fraction > 0) || o.min_centre_dots < 4 || !(o.smoothing >= 0) || o.degree < 1 || o.degree > 5 ||
      o.min_dots < 2 * terms || o.table_step < 1) {
    return invalid_argument(
        "lens correction: centre_fraction must be > 0, min_centre_dots >= 4, smoothing >= 0, degree 1..5, min_dots at "
        "least twice the polynomial's (degree + 1)(degree + 2)/2 terms and table_step >= 1");
  }
  const size_t n = dots.size();
  if (n < static_cast<size_t>(o.min_dots)) {
    return failed_precondition("lens correction: " + std::to_string(n) + " dots of the grid were indexed; at least " +
                               std::to_string(o.min_dots) +
                               " are needed (is the board in view, sharp and evenly lit?)");
  }
  for (const GridDot& d : dots)
    if (!d.centre.allFinite()) return invalid_argument("lens correction: a dot centre is not finite");

  // The ideal image: the homography of the grid places that fits the central dots.
  const Vector2d middle(0.5 * (width - 1), 0.5 * (height - 1));
  const double radius = o.centre_fraction * 0.5 * std::hypot(width, height);
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  auto distance = [&](size_t i) { return (dots[i].centre - middle).norm(); };
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return distance(a) < distance(b); });
  std::vector<Vector2d> places, centres;
  for (size_t i : order) {
    if (places.size() >= static_cast<size_t>(o.min_centre_dots) && distance(i) > radius) break;
    places.emplace_back(dots[i].col, dots[i].row);
    centres.push_back(dots[i].centre);
  }
  // Grid places all on one line (a single row of dots) leave the ideal image undetermined.
  Eigen::Matrix2d spread = Eigen::Matrix2d::Zero();
  for (const Vector2d& q : places) spread += (q - places.front()) * (q - places.front()).transpose();
  if (!(spread.determinant() > 0)) {
    return invalid_argument("lens correction: the central dots' grid places lie on one line");
  }
  ASSIGN_OR_RETURN(const Eigen::Matrix3d grid_to_image, fit_homography(places, centres));
  std::vector<Vector2d> captured(n), ideal(n);
  for (size_t i = 0; i < n; ++i) {
    captured[i] = dots[i].centre;
    ideal[i] = apply_homography(grid_to_image, Vector2d(dots[i].col, dots[i].row));
  }

  auto state = std::make_shared<State>();
  state->dots = dots;
  state->options = o;
  std::optional<PlateSpline> forward = PlateSpline::fit(captured, ideal, o.smoothing, o.degree);
  std::optional<PlateSpline> inverse = PlateSpline::fit(ideal, captured, o.smoothing, o.degree);
  if (!forward || !inverse) return invalid_argument("lens correction: the splines cannot be fitted (coincident dots?)");
  state->forward = std::move(*forward);
  state->inverse = std::move(*inverse);

  LensCorrection lens;
  lens.width_ = width;
  lens.height_ = height;
  lens.dots_used_ = static_cast<int>(n);
  std::vector<Vector2d> fitted(n);
  for (size_t i = 0; i < n; ++i) fitted[i] = state->forward(captured[i]);
  lens.fit_rms_ = rms(fitted, ideal);
  // Every fifth dot along the diagonals (col + 2 row = fold mod 5) is held out in
  // turn, so a held-out dot keeps its four neighbours; the figure is over the dots
  // that have all four, as it is the accuracy between dots, not the extrapolation
  // beyond the outermost ones.
  constexpr int kFolds = 5;
  std::unordered_set<int64_t> indexed;
  for (const GridDot& d : dots) indexed.insert(place_key(d.col, d.row));
  auto interior = [&](const GridDot& d) {
    return indexed.count(place_key(d.col - 1, d.row)) && indexed.count(place_key(d.col + 1, d.row)) &&
           indexed.count(place_key(d.col, d.row - 1)) && indexed.count(place_key(d.col, d.row + 1));
  };
  double held_out_ss = 0;
  int held_out = 0;
  for (int fold = 0; fold < kFolds; ++fold) {
    std::vector<Vector2d> from, to;
    std::vector<size_t> out;
    for (size_t i = 0; i < n; ++i) {
      if (((dots[i].col + 2 * dots[i].row) % kFolds + kFolds) % kFolds != fold) {
        from.push_back(captured[i]);
        to.push_back(ideal[i]);
      } else if (interior(dots[i])) {
        out.push_back(i);
      }
    }
    if (out.empty()) continue;
    const std::optional<PlateSpline> s = PlateSpline::fit(from, to, o.smoothing, o.degree);
    if (!s) return invalid_argument("lens correction: the splines cannot be fitted (coincident dots?)");
    for (size_t i : out) held_out_ss += ((*s)(captured[i]) - ideal[i]).squaredNorm();
    held_out += static_cast<int>(out.size());
  }
  lens.held_out_rms_ = held_out > 0 ? std::sqrt(held_out_ss / held_out) : 0.0;

  const double step = o.table_step, margin = 2 * step;
  state->forward_table =
      Table(state->forward, Vector2d::Constant(-margin), Vector2d(width - 1 + margin, height - 1 + margin), step);
  const auto [lo, hi] = state->forward_table.value_range();
  state->inverse_table = Table(state->inverse, lo, hi, step);
  lens.state_ = state;

  // A display does not need distort()'s last hundredth of a pixel.
  state->remap.resize(static_cast<size_t>(width) * height);
  tbb::parallel_for(0, height, [&](int y) {
    for (int x = 0; x < width; ++x) {
      const Vector2d s = lens.inverse_estimate(Vector2d(x, y));
      if (!(s.x() >= 0 && s.y() >= 0 && s.x() <= width - 1 && s.y() <= height - 1)) continue;
      const int sx = std::min(static_cast<int>(s.x()), width - 2), sy = std::min(static_cast<int>(s.y()), height - 2);
      RemapEntry& e = state->remap[static_cast<size_t>(y) * width + x];
      e.offset = sy * width + sx;
      e.fx = static_cast<uint16_t>(std::lround((s.x() - sx) * 32768));
      e.fy = static_cast<uint16_t>(std::lround((s.y() - sy) * 32768));
    }
  });
  return lens;
}

namespace {

// One Newton step on `forward` (its Jacobian by central differences) from `guess`
// towards forward(p) = ideal. The inverse splines are fitted apart from the forward
// ones and disagree with them by up to a few hundredths of a pixel near the corners;
// from their estimate, one step makes distort() invert correct() to ~1e-5 pixel.
template <typename Forward>
Vector2d newton_step(const Forward& forward, const Vector2d& guess, const Vector2d& ideal) {
  constexpr double kH = 0.5;
  Eigen::Matrix2d j;
  j.col(0) = (forward(guess + Vector2d(kH, 0)) - forward(guess - Vector2d(kH, 0))) / (2 * kH);
  j.col(1) = (forward(guess + Vector2d(0, kH)) - forward(guess - Vector2d(0, kH))) / (2 * kH);
  const Vector2d step = j.partialPivLu().solve(forward(guess) - ideal);
  return step.allFinite() ? Vector2d(guess - step) : guess;
}

}  // namespace

Eigen::Vector2d LensCorrection::correct(const Eigen::Vector2d& captured) const {
  if (!state_) return captured;
  Vector2d out;
  return state_->forward_table.at(captured, out) ? out : state_->forward(captured);
}

Eigen::Vector2d LensCorrection::distort(const Eigen::Vector2d& ideal) const {
  if (!state_) return ideal;
  return newton_step([this](const Vector2d& p) { return correct(p); }, inverse_estimate(ideal), ideal);
}

Eigen::Vector2d LensCorrection::inverse_estimate(const Eigen::Vector2d& ideal) const {
  Vector2d out;
  return state_->inverse_table.at(ideal, out) ? out : state_->inverse(ideal);
}

Eigen::Vector2d LensCorrection::correct_exact(const Eigen::Vector2d& captured) const {
  return state_ ? state_->forward(captured) : captured;
}

Eigen::Vector2d LensCorrection::distort_exact(const Eigen::Vector2d& ideal) const {
  return state_ ? newton_step(state_->forward, state_->inverse(ideal), ideal) : ideal;
}

StatusOr<std::vector<uint16_t>> LensCorrection::remap(const ImageView& image) const {
  if (!image.pixels || image.width <= 0 || image.height <= 0) return invalid_argument("lens remap: the image is empty");
  const size_t size = static_cast<size_t>(image.width) * image.height;
  if (!state_) return std::vector<uint16_t>(image.pixels, image.pixels + size);
  if (image.width != width_ || image.height != height_) {
    return invalid_argument("lens remap: the image is " + std::to_string(image.width) + " x " +
                            std::to_string(image.height) + " pixels but the correction was fitted to " +
                            std::to_string(width_) + " x " + std::to_string(height_));
  }
  std::vector<uint16_t> out(size, 0);
  const int w = width_;
  tbb::parallel_for(0, height_, [&](int y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      const RemapEntry& e = state_->remap[i];
      if (e.offset < 0) continue;
      const uint16_t* a = image.pixels + e.offset;
      const uint32_t top = a[0] * (32768u - e.fx) + a[1] * uint32_t{e.fx};
      const uint32_t bottom = a[w] * (32768u - e.fx) + a[w + 1] * uint32_t{e.fx};
      out[i] = static_cast<uint16_t>((uint64_t{top} * (32768u - e.fy) + uint64_t{bottom} * e.fy + (1u << 29)) >> 30);
    }
  });
  return out;
}

const std::vector<GridDot>& LensCorrection::grid_dots() const {
  static const std::vector<GridDot> none;
  return state_ ? state_->dots : none;
}

const LensOptions& LensCorrection::options() const {
  static const LensOptions defaults;
  return state_ ? state_->options : defaults;
}

StatusOr<LensCorrection> calibrate_lens(const ImageView& image, const LensOptions& o) {
  ASSIGN_OR_RETURN(const std::vector<Dot> dots, find_dots(image, o.dots));
  if (dots.empty()) {
    return failed_precondition("lens calibration: no dots found in the dot-grid image (is the board in view and lit?)");
  }
  const std::vector<GridDot> grid = index_grid(dots, o.grid);
  if (grid.size() < static_cast<size_t>(o.min_dots)) {
    return failed_precondition("lens calibration: " + std::to_string(dots.size()) + " dots found but only " +
                               std::to_string(grid.size()) + " form a grid; at least " + std::to_string(o.min_dots) +
                               " are needed (is the whole board in view and sharp?)");
  }
  ASSIGN_OR_RETURN(LensCorrection lens, LensCorrection::fit(grid, image.width, image.height, o));
  lens.dots_found_ = static_cast<int>(dots.size());
  return lens;
}

}  // namespace bodyscan
