#include "recon/surface/implicit_field.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <mutex>
#include <numeric>

#include "core/median.hpp"

namespace bodyscan {

namespace {

constexpr int kCoordBits = 21;
constexpr int kMaxCoord = (1 << kCoordBits) - 1;

// A kernel prepared for splatting: z = M (x - c) are its normalised local coordinates.
// Nodes are visited in the elliptic cylinder |(z1, z2)| < r across the tangent
// plane, cut by the slab |z3u| < slab along the normal (z3u = n . d / sn, the unbent
// normal coordinate); the slab is the support's normal extent, or the kernel's
// band when that is narrower, widened by the bend's largest sag. Each visited node
// is then tested against the true (bent) support |z| < r:
//   p  = b1 z1^2 + b2 z2^2                   (the paraboloid's sag, sigma_n units)
//   x  = c1 z1^2 + c2 z2^2                   (bend1^2 t1^2 + bend2^2 t2^2, world)
//   z3 = z3u + p * 2 / (1 + sqrt(1 - min(1, x)))   (the circle's sag).
struct Prepared {
  Eigen::Matrix3f m;  // rows t1/s1, t2/s2, n/sn
  // The visited region lies inside the ellipsoid (x - c)^T A (x - c) <= 2 r^2,
  // A = M^T diag(1, 1, (r / slab)^2) M; per grid layer z its y extent bounds the
  // rows worth looking at (a tilted disk's box is mostly empty).
  float yy = 0.f, yz = 0.f, zz = 0.f;  // y-extent quadratic at fixed z (Schur complement of A)
  Vec3f center;
  Vec3f half_extent;  // world-axis half size of the visited region
  float weight;
  float slab;
  float b1, b2;
  float c1, c2;  // bend_a^2 sigma_t_a^2
  bool exact;    // the support reaches x > 1/4 (splat_row_body)
};

// The sag of a sphere of curvature |bend| at tangential distance r (world units),
// from the paraboloid's bend r^2 / 2: exact up to r = 1 / |bend|, then |bend| r^2.
float sphere_sag(float bend, float r) {
  const float parabola = 0.5f * std::abs(bend) * r * r;
  const float x = std::min(1.f, bend * bend * r * r);
  return parabola * 2.f / (1.f + std::sqrt(1.f - x));
}

Prepared prepare(const Kernel& k, float r) {
  Prepared p;
  const float sag = sphere_sag(std::max(std::abs(k.bend1), std::abs(k.bend2)), r * std::max(k.sigma_t1, k.sigma_t2));
  const float normal_reach = k.band > 0.f ? std::min(k.band, r * k.sigma_n) : r * k.sigma_n;
  const float slab_mm = normal_reach + sag;
  p.m.row(0) = k.t1.transpose() / k.sigma_t1;
  p.m.row(1) = k.t2.transpose() / k.sigma_t2;
  p.m.row(2) = k.n.transpose() / k.sigma_n;
  p.center = k.center;
  for (int j = 0; j < 3; ++j) {
    const float a = k.sigma_t1 * k.t1[j], b = k.sigma_t2 * k.t2[j];
    p.half_extent[j] = r * std::sqrt(a * a + b * b) + slab_mm * std::abs(k.n[j]);
  }
  p.weight = k.weight;
  p.slab = slab_mm / k.sigma_n;
  Eigen::Matrix3f scaled = p.m;
  scaled.row(2) *= r / p.slab;
  const Eigen::Matrix3f a = scaled.transpose() * scaled;
  p.yy = a(1, 1) - a(0, 1) * a(0, 1) / a(0, 0);
  p.yz = a(1, 2) - a(0, 1) * a(0, 2) / a(0, 0);
  p.zz = a(2, 2) - a(0, 2) * a(0, 2) / a(0, 0);
  p.b1 = 0.5f * k.bend1 * k.sigma_t1 * k.sigma_t1 / k.sigma_n;
  p.b2 = 0.5f * k.bend2 * k.sigma_t2 * k.sigma_t2 / k.sigma_n;
  p.c1 = k.bend1 * k.bend1 * k.sigma_t1 * k.sigma_t1;
  p.c2 = k.bend2 * k.bend2 * k.sigma_t2 * k.sigma_t2;
  p.exact = std::max(p.c1, p.c2) * r * r > 0.25f;
  return p;
}

// exp(x) for x <= 0, relative error < 2e-7 (x >= -87; 0 below): 2^(x log2 e) split into an
// integer power (built in the exponent bits) and a degree-6 polynomial on [0, 1).
// Branch-free, so the splatting loop vectorises; std::exp does not.
__attribute__((always_inline)) inline float exp_nonpositive(float x) {
  x = x > -87.f ? x : -87.f;
  const float y = x * 1.44269504089f;
  // floor(y) by truncating a positive number: SSE2 has no floor instruction, and
  // a libm call would stop the vectoriser.
  const int32_t i = static_cast<int32_t>(y + 128.f) - 128;
  const float f = y - static_cast<float>(i);
  // Least-squares fit of 2^f on [0, 1] for relative error (max 1.1e-7 in float).
  float p = 2.168343131e-4f;
  p = p * f + 1.243794637e-3f;
  p = p * f + 9.679985257e-3f;
  p = p * f + 5.548215028e-2f;
  p = p * f + 2.402303083e-1f;
  p = p * f + 6.931469140e-1f;
  p = p * f + 1.000000004f;
  int32_t bits;
  std::memcpy(&bits, &p, sizeof bits);
  bits += i * (1 << 23);
  float out;
  std::memcpy(&out, &bits, sizeof out);
  return out;
}

// Adds one kernel to nodes t0 .. t0 + n - 1 of a grid row (f and w point at node
// t0). z = (zx, zy, zz) + t d are the kernel's (unbent) local coordinates at node t,
// computed from the row's own start so that a node gets the same float value
// whichever brick it is in. Written as plain scalars
// with restrict pointers and selects so that GCC vectorises it (the file is built
// with -fno-trapping-math, which lets it turn the selects into masks).
// A node takes the kernel's contribution exactly when it lies in the bent support
// (q < r2) and in the normal slab; the caller may pass any superset of those nodes
// (whole 8-node chunks, so the vector loop needs no scalar tail) without changing
// a single value.
//
// The circle's sag from the paraboloid's: sag * 2 / (1 + sqrt(1 - x)), x =
// c1 z1^2 + c2 z2^2 <= 1. Kernels whose support keeps x <= 1/4 (every kernel of a densely
// sampled surface) use that factor's series sum_n Catalan(n) (x / 4)^n to the fifth
// term (relative error < 6e-5 there), which costs four multiply-adds instead of a
// square root and a division.
template <bool kExact>
__attribute__((always_inline)) inline void splat_row_body(float* __restrict f, float* __restrict w, int t0, int n,
                                                          float zx, float zy, float zz, float dx, float dy, float dz,
                                                          float b1, float b2, float c1, float c2, float weight,
                                                          float r2, float slab2) {
  for (int t = 0; t < n; ++t) {
    const float tf = static_cast<float>(t0 + t);
    const float z1 = zx + tf * dx, z2 = zy + tf * dy, z3u = zz + tf * dz;
    const float z1s = z1 * z1, z2s = z2 * z2;
    const float sag = b1 * z1s + b2 * z2s;
    float z3;
    if constexpr (kExact) {
      const float x = std::min(c1 * z1s + c2 * z2s, 1.f);
      z3 = z3u + sag * 2.f / (1.f + std::sqrt(1.f - x));
    } else {
      const float y = 0.25f * (c1 * z1s + c2 * z2s);
      z3 = z3u + sag * (1.f + y * (1.f + y * (2.f + y * (5.f + y * 14.f))));
    }
    const float q = z1s + z2s + z3 * z3;
    const bool inside = (q < r2) & (z3u * z3u < slab2);
    const float wt = inside ? weight : 0.f;
    const float e = wt * exp_nonpositive(-0.5f * q);
    f[t] += -z3 * e;
    w[t] += e;
  }
}

// Cloned for x86-64-v3 (AVX2, FMA), chosen at load time by the CPU's features. A
// clone for a named CPU ("arch=haswell") is chosen by the CPU's model instead, and
// so never runs on later models nor in virtual machines that hide the model.
__attribute__((target_clones("arch=x86-64-v3", "default"))) void splat_row_series(
    float* __restrict f, float* __restrict w, int t0, int n, float zx, float zy, float zz, float dx, float dy, float dz,
    float b1, float b2, float c1, float c2, float weight, float r2, float slab2) {
  splat_row_body<false>(f, w, t0, n, zx, zy, zz, dx, dy, dz, b1, b2, c1, c2, weight, r2, slab2);
}

__attribute__((target_clones("arch=x86-64-v3", "default"))) void splat_row_exact(
    float* __restrict f, float* __restrict w, int t0, int n, float zx, float zy, float zz, float dx, float dy, float dz,
    float b1, float b2, float c1, float c2, float weight, float r2, float slab2) {
  splat_row_body<true>(f, w, t0, n, zx, zy, zz, dx, dy, dz, b1, b2, c1, c2, weight, r2, slab2);
}

struct Pair {
  uint64_t key;
  uint32_t kernel;
  bool operator<(const Pair& o) const { return key != o.key ? key < o.key : kernel < o.kernel; }
};

}  // namespace

uint64_t ImplicitField::pack(const Eigen::Vector3i& c) {
  return (static_cast<uint64_t>(c.z()) << (2 * kCoordBits)) | (static_cast<uint64_t>(c.y()) << kCoordBits) |
         static_cast<uint64_t>(c.x());
}

Eigen::Vector3i ImplicitField::brick_coord(size_t b) const {
  const uint64_t k = keys_[b];
  return {static_cast<int>(k & kMaxCoord), static_cast<int>((k >> kCoordBits) & kMaxCoord),
          static_cast<int>(k >> (2 * kCoordBits))};
}

long ImplicitField::find_brick(const Eigen::Vector3i& c) const {
  if ((c.array() < 0).any() || (c.array() > kMaxCoord).any()) return -1;
  const uint64_t k = pack(c);
  auto it = std::lower_bound(keys_.begin(), keys_.end(), k);
  if (it == keys_.end() || *it != k) return -1;
  return static_cast<long>(it - keys_.begin());
}

size_t ImplicitField::memory_bytes() const {
  return keys_.capacity() * sizeof(uint64_t) + blocks_.capacity() * sizeof(blocks_[0]) +
         blocks_.size() * 2 * nodes_per_brick() * sizeof(float);
}

float ImplicitField::value_at(const Eigen::Vector3i& node) const {
  const long b = find_brick({node.x() >> brick_shift_, node.y() >> brick_shift_, node.z() >> brick_shift_});
  if (b < 0) return 0.f;
  const int m = brick_size_ - 1;
  return values(static_cast<size_t>(b))[(node.x() & m) + brick_size_ * ((node.y() & m) + brick_size_ * (node.z() & m))];
}

float ImplicitField::weight_at(const Eigen::Vector3i& node) const {
  const long b = find_brick({node.x() >> brick_shift_, node.y() >> brick_shift_, node.z() >> brick_shift_});
  if (b < 0) return 0.f;
  const int m = brick_size_ - 1;
  return weights(
      static_cast<size_t>(b))[(node.x() & m) + brick_size_ * ((node.y() & m) + brick_size_ * (node.z() & m))];
}

void ImplicitField::evaluate(const std::vector<Kernel>& kernels, float epsilon, const Vec3d& x, double* value,
                             double* weight) {
  const double r2 = -2.0 * std::log(static_cast<double>(epsilon));
  const float r = static_cast<float>(std::sqrt(r2));
  double f = 0.0, w = 0.0;
  for (const Kernel& k : kernels) {
    const double slab = prepare(k, r).slab;  // the same normal band as the grid
    const Vec3d d = x - k.center.cast<double>();
    const double z1 = d.dot(k.t1.cast<double>()) / k.sigma_t1;
    const double z2 = d.dot(k.t2.cast<double>()) / k.sigma_t2;
    const double z3u = d.dot(k.n.cast<double>()) / k.sigma_n;
    const double u2 = z1 * z1 * k.sigma_t1 * k.sigma_t1, v2 = z2 * z2 * k.sigma_t2 * k.sigma_t2;
    const double b1 = k.bend1, b2 = k.bend2;
    const double parabola = 0.5 * (b1 * u2 + b2 * v2);
    const double bent = std::min(1.0, b1 * b1 * u2 + b2 * b2 * v2);
    const double z3 = z3u + parabola * 2.0 / (1.0 + std::sqrt(1.0 - bent)) / k.sigma_n;
    const double q = z1 * z1 + z2 * z2 + z3 * z3;
    if (q >= r2 || std::abs(z3u) >= slab) continue;
    const double e = k.weight * std::exp(-0.5 * q);
    f += -z3 * e;
    w += e;
  }
  *value = f;
  *weight = w;
}

StatusOr<ImplicitField> build_implicit_field(const std::vector<Kernel>& kernels, const ImplicitFieldOptions& options) {
  if (!(options.voxel_size > 0.f) || !std::isfinite(options.voxel_size)) {
    return invalid_argument("voxel size must be a positive number");
  }
  if (!(options.epsilon > 0.f && options.epsilon < 1.f)) {
    return invalid_argument("error tolerance epsilon must be in (0, 1)");
  }
  const int bs = options.brick_size;
  if (bs < 2 || bs > 1024 || (bs & (bs - 1)) != 0) {
    return invalid_argument("brick size must be a power of two in [2, 1024]");
  }
  if (kernels.empty()) return invalid_argument("no points to build a surface from");

  ImplicitField field;
  field.voxel_size_ = options.voxel_size;
  field.brick_size_ = bs;
  field.brick_shift_ = 0;
  while ((1 << field.brick_shift_) < bs) ++field.brick_shift_;

  const float r2 = -2.f * std::log(options.epsilon);
  const float r = std::sqrt(r2);
  const double h = options.voxel_size;

  std::vector<Prepared> prep(kernels.size());
  tbb::parallel_for(size_t{0}, kernels.size(), [&](size_t i) { prep[i] = prepare(kernels[i], r); });

  Vec3d lo = Vec3d::Constant(std::numeric_limits<double>::max());
  Vec3d hi = Vec3d::Constant(std::numeric_limits<double>::lowest());
  for (const Prepared& p : prep) {
    if (!p.center.allFinite() || !p.half_extent.allFinite() || !(p.weight > 0.f)) {
      return invalid_argument("a kernel has a non-finite position or size, or a weight <= 0");
    }
    lo = lo.cwiseMin((p.center - p.half_extent).cast<double>());
    hi = hi.cwiseMax((p.center + p.half_extent).cast<double>());
  }
  // Align the grid to multiples of the voxel size so that the nodes do not depend
  // on the cloud's extent beyond that: the same points give the same grid.
  field.origin_ = ((lo / h).array().floor() - 1.0).matrix() * h;
  const Vec3d span = (hi - field.origin_) / h;
  if ((span.array() + 2.0 > static_cast<double>(kMaxCoord)).any()) {
    return out_of_range("the voxel size is too small for the cloud's extent (more than " + std::to_string(kMaxCoord) +
                        " voxels along an axis)");
  }

  // Node range of each kernel's support.
  const size_t nk = prep.size();
  std::vector<Eigen::Vector3i> klo(nk), khi(nk);
  tbb::parallel_for(size_t{0}, nk, [&](size_t i) {
    const Prepared& p = prep[i];
    const Vec3d a = ((p.center - p.half_extent).cast<double>() - field.origin_) / h;
    const Vec3d b = ((p.center + p.half_extent).cast<double>() - field.origin_) / h;
    klo[i] = a.array().ceil().cast<int>().max(0);
    khi[i] = b.array().floor().cast<int>();
  });
  auto empty_range = [&](size_t i) { return (khi[i].array() < klo[i].array()).any(); };

  // Work is split into pencils: rows of bricks along x with one (y, z) brick
  // coordinate. A kernel visits each pencil it overlaps once and splats whole grid
  // rows there, split only where they cross bricks, so rows stay long; and two
  // pencils never share a node, so they run in parallel without locks.
  const int bs_shift = field.brick_shift_;
  std::vector<size_t> counts(nk + 1, 0);
  tbb::parallel_for(size_t{0}, nk, [&](size_t i) {
    if (empty_range(i)) return;
    const Eigen::Vector3i blo = klo[i].array() / bs, bhi = khi[i].array() / bs;
    counts[i + 1] = static_cast<size_t>(bhi.y() - blo.y() + 1) * static_cast<size_t>(bhi.z() - blo.z() + 1);
  });
  std::partial_sum(counts.begin(), counts.end(), counts.begin());
  if (counts.back() > 200'000'000ull) {
    return out_of_range("the kernels are too large for the voxel size (" + std::to_string(counts.back()) +
                        " kernel-pencil overlaps): use a larger voxel size");
  }
  std::vector<Pair> pairs(counts.back());
  tbb::parallel_for(size_t{0}, nk, [&](size_t i) {
    if (empty_range(i)) return;
    const Eigen::Vector3i blo = klo[i].array() / bs, bhi = khi[i].array() / bs;
    size_t o = counts[i];
    for (int z = blo.z(); z <= bhi.z(); ++z)
      for (int y = blo.y(); y <= bhi.y(); ++y) pairs[o++] = {ImplicitField::pack({0, y, z}), static_cast<uint32_t>(i)};
  });
  std::vector<size_t>().swap(counts);
  tbb::parallel_sort(pairs.begin(), pairs.end());
  if (!report(options.progress, "field", 0.1)) return cancelled("reconstruction cancelled");

  std::vector<size_t> starts;  // each pencil's slice of `pairs`
  for (size_t i = 0; i < pairs.size(); ++i)
    if (i == 0 || pairs[i].key != pairs[i - 1].key) starts.push_back(i);
  starts.push_back(pairs.size());
  const size_t np = starts.size() - 1;

  // Phase 1: each pencil's x extent and the bricks its kernels' boxes overlap (the
  // union of their x ranges): the bound that max_bricks is checked against before
  // anything is allocated.
  std::vector<std::vector<int>> pencil_bricks(np);
  tbb::parallel_for(size_t{0}, np, [&](size_t pc) {
    int xmin = INT32_MAX, xmax = INT32_MIN;
    for (size_t pi = starts[pc]; pi < starts[pc + 1]; ++pi) {
      xmin = std::min(xmin, klo[pairs[pi].kernel].x() >> bs_shift);
      xmax = std::max(xmax, khi[pairs[pi].kernel].x() >> bs_shift);
    }
    std::vector<uint8_t> used(static_cast<size_t>(xmax - xmin + 1), 0);
    for (size_t pi = starts[pc]; pi < starts[pc + 1]; ++pi) {
      const uint32_t k = pairs[pi].kernel;
      for (int x = klo[k].x() >> bs_shift; x <= (khi[k].x() >> bs_shift); ++x) used[x - xmin] = 1;
    }
    for (int x = xmin; x <= xmax; ++x)
      if (used[x - xmin]) pencil_bricks[pc].push_back(x);
  });
  size_t nb = 0;  // at most; only those some kernel's band reaches are allocated
  for (const std::vector<int>& xs : pencil_bricks) nb += xs.size();
  if (nb > options.max_bricks) {
    return out_of_range("the surface needs " + std::to_string(nb) + " bricks, more than the limit of " +
                        std::to_string(options.max_bricks) + ": use a larger voxel size");
  }
  const size_t per = field.nodes_per_brick();
  // Each pencil's bricks as its kernels first reach them (x brick coordinate, block).
  std::vector<std::vector<std::pair<int, std::unique_ptr<float[]>>>> pencil_blocks(np);

  // Phase 2: splat.
  std::atomic<size_t> done{0};
  std::atomic<bool> stop{false};
  std::mutex progress_mutex;  // the callback is not required to be thread-safe
  double last_fraction = 0.1;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, np, 4), [&](const tbb::blocked_range<size_t>& range) {
    if (stop.load(std::memory_order_relaxed)) return;
    std::vector<float*> block_of;  // x brick coordinate - xmin -> block, null until reached
    for (size_t pc = range.begin(); pc != range.end(); ++pc) {
      const uint64_t yz = pairs[starts[pc]].key;
      const int by = static_cast<int>((yz >> kCoordBits) & kMaxCoord);
      const int bz = static_cast<int>(yz >> (2 * kCoordBits));
      const std::vector<int>& xs = pencil_bricks[pc];
      const int xmin = xs.front();
      block_of.assign(static_cast<size_t>(xs.back() - xmin + 1), nullptr);
      auto& blocks = pencil_blocks[pc];
      const int y_first = by * bs, z_first = bz * bs;
      for (size_t pi = starts[pc]; pi < starts[pc + 1]; ++pi) {
        const uint32_t ki = pairs[pi].kernel;
        const Prepared& p = prep[ki];
        const Eigen::Vector3i& node_lo = klo[ki];
        const Eigen::Vector3i& node_hi = khi[ki];
        // z at the kernel's first node and its steps along x, y, z, all from
        // integer offsets: a node's value does not depend on the brick size.
        const Vec3f zb = p.m * (field.origin_ + h * node_lo.cast<double>() - p.center.cast<double>()).cast<float>();
        const Vec3f dx = p.m.col(0) * static_cast<float>(h);
        const Vec3f dy = p.m.col(1) * static_cast<float>(h);
        const Vec3f dz = p.m.col(2) * static_cast<float>(h);
        const float dd12 = dx.x() * dx.x() + dx.y() * dx.y();
        // Reciprocals once per kernel rather than per row. Rounding may move a
        // row's ends by a hair, so they are widened by 1e-3 node: the per-node test in
        // splat_row decides exactly which nodes take the kernel.
        const float inv_dd12 = dd12 > 1e-12f ? 1.f / dd12 : 0.f;
        const float inv_dxz = std::abs(dx.z()) > 1e-12f ? 1.f / dx.z() : 0.f;
        const float cy = (p.center.y() - static_cast<float>(field.origin_.y())) / static_cast<float>(h);
        const float inv_yy_h = 1.f / (p.yy * static_cast<float>(h));
        const float t_max = static_cast<float>(node_hi.x() - node_lo.x());
        const int z0i = std::max(node_lo.z(), z_first), z1i = std::min(node_hi.z(), z_first + bs - 1);
        const int y0i = std::max(node_lo.y(), y_first), y1i = std::min(node_hi.y(), y_first + bs - 1);
        const float r2x2 = 2.f * r2;
        for (int z = z0i; z <= z1i; ++z) {
          const Vec3f zz = zb + static_cast<float>(z - node_lo.z()) * dz;
          // y extent of the bounding ellipsoid in this layer: yy t^2 + 2 yz dzw t + zz dzw^2 <= 2 r^2.
          const float dzw = static_cast<float>(field.origin_.z() + h * z) - p.center.z();
          const float bq_y = p.yz * dzw;
          const float disc_y = bq_y * bq_y - p.yy * (p.zz * dzw * dzw - r2x2);
          if (disc_y <= 0.f) continue;
          const float sq_y = std::sqrt(disc_y);
          const float ylo_f = cy + (-bq_y - sq_y) * inv_yy_h;
          const float yhi_f = cy + (-bq_y + sq_y) * inv_yy_h;
          const int ya = std::max(y0i, static_cast<int>(std::floor(ylo_f)));
          const int yb = std::min(y1i, static_cast<int>(std::ceil(yhi_f)));
          for (int y = ya; y <= yb; ++y) {
            const Vec3f z0 = zz + static_cast<float>(y - node_lo.y()) * dy;
            // Cylinder: |z0_12 + t dx_12|^2 < r2; slab: |z0_3 + t dx_3| < slab.
            float lo_f = 0.f, hi_f = t_max;
            const float bq = z0.x() * dx.x() + z0.y() * dx.y();
            const float cq = z0.x() * z0.x() + z0.y() * z0.y() - r2;
            if (dd12 > 1e-12f) {
              const float disc = bq * bq - dd12 * cq;
              if (disc <= 0.f) continue;
              const float sq = std::sqrt(disc);
              lo_f = std::max(lo_f, (-bq - sq) * inv_dd12 - 1e-3f);
              hi_f = std::min(hi_f, (-bq + sq) * inv_dd12 + 1e-3f);
            } else if (cq >= 0.f) {
              continue;  // the row runs along the normal, outside the cylinder
            }
            if (std::abs(dx.z()) > 1e-12f) {
              const float s0 = (-p.slab - z0.z()) * inv_dxz, s1 = (p.slab - z0.z()) * inv_dxz;
              lo_f = std::max(lo_f, std::min(s0, s1) - 1e-3f);
              hi_f = std::min(hi_f, std::max(s0, s1) + 1e-3f);
            } else if (std::abs(z0.z()) >= p.slab) {
              continue;
            }
            if (hi_f < lo_f) continue;
            // ceil / floor of non-negative numbers without libm calls.
            int t_lo = static_cast<int>(lo_f);
            if (static_cast<float>(t_lo) < lo_f) ++t_lo;
            const int t_hi = static_cast<int>(hi_f);
            if (t_hi < t_lo) continue;
            const int row_offset = (y - y_first) * bs + (z - z_first) * bs * bs;
            // Split the row where it crosses bricks; within a brick widen the
            // segment to whole 8-node chunks when the brick allows.
            for (int gx = node_lo.x() + t_lo; gx <= node_lo.x() + t_hi;) {
              const int bx = gx >> bs_shift;
              const int brick_x = bx << bs_shift;
              const int seg_end = std::min(node_lo.x() + t_hi, brick_x + bs - 1);
              int first = gx - brick_x, last = seg_end - brick_x;
              if (bs % 8 == 0) {
                first &= ~7;
                last |= 7;
              }
              float*& block = block_of[static_cast<size_t>(bx - xmin)];
              if (block == nullptr) {
                blocks.emplace_back(bx, std::make_unique<float[]>(2 * per));  // zeroed
                block = blocks.back().second.get();
              }
              float* const values = block + row_offset + first;
              (p.exact ? splat_row_exact : splat_row_series)(
                  values, values + per, brick_x + first - node_lo.x(), last - first + 1, z0.x(), z0.y(), z0.z(), dx.x(),
                  dx.y(), dx.z(), p.b1, p.b2, p.c1, p.c2, p.weight, r2, p.slab * p.slab);
              gx = seg_end + 1;
            }
          }
        }
      }
      std::sort(blocks.begin(), blocks.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    }
    const size_t d = done.fetch_add(range.size()) + range.size();
    if (options.progress) {
      std::lock_guard<std::mutex> lock(progress_mutex);
      // Under the lock, so that reports never go backwards.
      last_fraction =
          std::max(last_fraction, std::min(1.0, 0.1 + 0.9 * static_cast<double>(d) / static_cast<double>(np)));
      if (!options.progress("field", last_fraction)) stop = true;
    }
  });
  if (stop) return cancelled("reconstruction cancelled");
  size_t allocated = 0;
  for (const auto& blocks : pencil_blocks) allocated += blocks.size();
  field.keys_.reserve(allocated);
  field.blocks_.reserve(allocated);
  for (size_t pc = 0; pc < np; ++pc) {
    const uint64_t yz = pairs[starts[pc]].key;  // x bits are 0
    for (auto& [x, block] : pencil_blocks[pc]) {
      field.keys_.push_back(yz | static_cast<uint64_t>(x));
      field.blocks_.push_back(std::move(block));
    }
  }
  return field;
}

float median_surface_weight(const ImplicitField& field, const std::vector<Vec3f>& points, size_t max_samples) {
  if (points.empty()) return 0.f;
  const size_t stride = std::max<size_t>(1, points.size() / std::max<size_t>(1, max_samples));
  std::vector<float> w;
  for (size_t i = 0; i < points.size(); i += stride) {
    const Vec3d g = (points[i].cast<double>() - field.origin()) / field.voxel_size();
    const Eigen::Vector3i node = g.array().round().cast<int>();
    if ((node.array() < 0).any()) continue;
    const float wi = field.weight_at(node);
    if (wi > 0.f) w.push_back(wi);
  }
  return median_in_place(w);
}

}  // namespace bodyscan
