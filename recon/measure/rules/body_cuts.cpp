#include "recon/measure/rules/body_cuts.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>

#include "recon/measure/plane_section.hpp"

namespace bodyscan::rules {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

int64_t level_key(double y) { return static_cast<int64_t>(std::llround(y * 64)); }

}  // namespace

BodyCuts::BodyCuts(const TriangleMesh& body, const BodyFrame& frame, double step_mm) : frame_(frame), body_(body) {
  double lo = kInf, hi = -kInf;
  for (const Vec3f& v : body_.vertices) {
    if (v.y() > hi) hi = v.y(), crown_ = v.cast<double>();
    lo = std::min(lo, static_cast<double>(v.y()));
  }
  stature_ = body_.vertices.empty() ? 0 : hi;
  if (!body_.vertices.empty()) slicer_.emplace(body_, lo, hi, step_mm);
}

Status BodyCuts::find_midline() {
  if (!slicer_) return invalid_argument("measure: the mesh has no vertices");
  const Ring* best = nullptr;
  for (const Ring& r : at(level(0.55)))
    if (!best || r.girth > best->girth) best = &r;
  if (!best) return not_found("measure: nothing at 55 % of the height; is the body standing on the floor?");
  midline_x_ = best->centroid.x();
  midline_z_ = best->centroid.z();
  return Status();
}

const std::vector<Ring>& BodyCuts::at(double y) const {
  const int64_t key = level_key(y);
  auto it = cache_.find(key);
  if (it == cache_.end()) it = cache_.emplace(key, slicer_->rings(static_cast<double>(key) / 64)).first;
  return it->second;
}

void BodyCuts::prefetch(double y0, double y1, double step) const {
  std::vector<int64_t> keys;
  for (double y = y0; step > 0 ? y <= y1 : y >= y1; y += step)
    if (const int64_t key = level_key(y); !cache_.count(key)) keys.push_back(key);
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  std::vector<std::vector<Ring>> made(keys.size());
  tbb::parallel_for(size_t{0}, keys.size(),
                    [&](size_t i) { made[i] = slicer_->rings(static_cast<double>(keys[i]) / 64); });
  for (size_t i = 0; i < keys.size(); ++i) cache_.emplace(keys[i], std::move(made[i]));
}

const Ring* BodyCuts::midline_loop(double y) const { return midline_ring(at(y), midline_x_); }

double BodyCuts::front_z(double y) const {
  double front = midline_z_, back = midline_z_;
  if (const Ring* m = midline_loop(y)) m->crossing_z(midline_x_, &front, &back);
  return front;
}

const Ring* BodyCuts::arm_loop(const std::vector<Ring>& cut, Side side) const {
  return side_ring(cut, midline_x_, side, true, 0.05 * stature_);
}

bool BodyCuts::arm_clear(double y, Side side) const {
  const std::vector<Ring>& cut = at(y);
  const Ring* arm = arm_loop(cut, side);
  const Ring* trunk = midline_ring(cut, midline_x_);
  return arm && !(trunk && arm->crosses(*trunk));
}

StatusOr<Girth> BodyCuts::level_girth(double y, const Eigen::Vector3d& near) const { return slicer_->girth(y, near); }

std::vector<uint32_t> BodyCuts::triangles_near(const Eigen::Vector3d& c, double r,
                                               const std::vector<uint32_t>& among) const {
  std::vector<uint32_t> out;
  const auto r2 = static_cast<float>(r * r);
  const Vec3f cf = c.cast<float>();
  const size_t n = among.empty() ? body_.triangles.size() : among.size();
  for (size_t i = 0; i < n; ++i) {
    const uint32_t t = among.empty() ? static_cast<uint32_t>(i) : among[i];
    for (uint32_t v : body_.triangles[t])
      if ((body_.vertices[v] - cf).squaredNorm() <= r2) {
        out.push_back(t);
        break;
      }
  }
  return out;
}

const Ring* midline_ring(const std::vector<Ring>& rings, double x) {
  const Ring* best = nullptr;
  for (const Ring& r : rings)
    if (r.spans_x(x) && (!best || r.girth > best->girth)) best = &r;
  return best;
}

namespace {
// Whether `r` lies wholly on `side` of the midline X = x, at least min_girth round.
bool on_side(const Ring& r, double x, Side side, double min_girth) {
  return !r.spans_x(x) && r.girth >= min_girth && sign(side) * (r.centroid.x() - x) > 0;
}
}  // namespace

const Ring* side_ring(const std::vector<Ring>& rings, double x, Side side, bool farthest, double min_girth) {
  const Ring* best = nullptr;
  double best_d = 0;
  for (const Ring& r : rings) {
    if (!on_side(r, x, side, min_girth)) continue;
    const double d = sign(side) * (r.centroid.x() - x);
    if (!best || (farthest ? d > best_d : d < best_d)) best = &r, best_d = d;
  }
  return best;
}

const Ring* nearest_side_ring(const std::vector<Ring>& rings, double x, Side side, const Eigen::Vector3d& last) {
  const Ring* best = nullptr;
  double best_d = kInf;
  for (const Ring& r : rings) {
    if (!on_side(r, x, side, kMinPartGirthMm)) continue;
    const double d = std::hypot(r.centroid.x() - last.x(), r.centroid.z() - last.z());
    if (d < best_d) best = &r, best_d = d;
  }
  return best;
}

size_t parts_near(const std::vector<Ring>& rings, const Ring& part, double reach, double min_girth) {
  size_t n = 0;
  for (const Ring& r : rings)
    if (&r != &part && r.girth >= min_girth && (r.centroid - part.centroid).norm() < reach) ++n;
  return n;
}

Eigen::Vector3d middle_of_extreme(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& dir,
                                  const Eigen::Vector3d& across, double band, bool between) {
  double top = -kInf;
  for (const Eigen::Vector3d& p : pts) top = std::max(top, p.dot(dir));
  double lo = kInf, hi = -kInf;
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d atb = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : pts)
    if (p.dot(dir) >= top - band) {
      const double t = p.dot(across);
      lo = std::min(lo, t), hi = std::max(hi, t);
      const Eigen::Vector3d row(t * t, t, 1);
      ata += row * row.transpose(), atb += row * p.dot(dir);
    }
  double mid = 0.5 * (lo + hi);
  const Eigen::Vector3d c = ata.ldlt().solve(atb);
  if (c.x() < 0 && -c.y() / (2 * c.x()) > lo && -c.y() / (2 * c.x()) < hi) mid = -c.y() / (2 * c.x());
  Eigen::Vector3d best = pts.front();
  double best_d = kInf;
  const Eigen::Vector3d* below = nullptr;  // the nearest points either side of the middle
  const Eigen::Vector3d* above = nullptr;
  for (const Eigen::Vector3d& p : pts) {
    if (p.dot(dir) < top - band) continue;
    const double t = p.dot(across);
    if (std::abs(t - mid) < best_d) best_d = std::abs(t - mid), best = p;
    if (t <= mid && (!below || t > below->dot(across))) below = &p;
    if (t >= mid && (!above || t < above->dot(across))) above = &p;
  }
  if (between && below && above && above->dot(across) > below->dot(across)) {
    const double f = (mid - below->dot(across)) / (above->dot(across) - below->dot(across));
    return *below + f * (*above - *below);
  }
  return best;
}

std::optional<Eigen::Vector3d> ray_exit(const std::vector<Eigen::Vector3d>& loop, const Eigen::Vector3d& origin,
                                        const Eigen::Vector3d& dir, const Eigen::Vector3d& across) {
  std::optional<Eigen::Vector3d> out;
  double far = 0;
  for (size_t i = 0, n = loop.size(); i < n; ++i) {
    const Eigen::Vector3d& a = loop[i];
    const Eigen::Vector3d& b = loop[(i + 1) % n];
    const double va = (a - origin).dot(across), vb = (b - origin).dot(across);
    if ((va < 0) == (vb < 0) || va == vb) continue;
    const double f = va / (va - vb);
    const Eigen::Vector3d q = a + f * (b - a);
    if (const double t = (q - origin).dot(dir); t > far) far = t, out = q;
  }
  return out;
}

Eigen::Vector3d loop_centre(const std::vector<Eigen::Vector3d>& loop) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double len = 0;
  for (size_t i = 0, n = loop.size(); i < n; ++i) {
    const Eigen::Vector3d& a = loop[i];
    const Eigen::Vector3d& b = loop[(i + 1) % n];
    const double l = (b - a).norm();
    sum += 0.5 * l * (a + b), len += l;
  }
  return len > 0 ? (sum / len).eval() : (loop.empty() ? Eigen::Vector3d::Zero() : loop.front());
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> fit_line(const std::vector<Eigen::Vector3d>& p, size_t b, size_t e,
                                                     double* residual, const std::vector<double>* weights) {
  const auto w = [&](size_t i) { return weights ? (*weights)[i] : 1.0; };
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  double total = 0;
  for (size_t i = b; i < e; ++i) c += w(i) * p[i], total += w(i);
  c /= total;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (size_t i = b; i < e; ++i) cov += w(i) * (p[i] - c) * (p[i] - c).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  Eigen::Vector3d d = es.eigenvectors().col(2);
  if (d.y() < 0) d = -d;
  if (residual) *residual = es.eigenvalues()(0) + es.eigenvalues()(1);
  return {c, d};
}

bool winds_round(const std::vector<Eigen::Vector3d>& loop, const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
  Eigen::Vector3d u, v;
  plane_basis(n, &u, &v);
  double turn = 0;
  for (size_t i = 0; i < loop.size(); ++i) {
    const Eigen::Vector3d a = loop[i] - p, b = loop[(i + 1) % loop.size()] - p;
    turn += std::atan2(a.dot(u) * b.dot(v) - a.dot(v) * b.dot(u), a.dot(u) * b.dot(u) + a.dot(v) * b.dot(v));
  }
  return std::abs(turn) > M_PI;
}

}  // namespace bodyscan::rules
