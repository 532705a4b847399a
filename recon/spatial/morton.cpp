#include "recon/spatial/morton.hpp"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <utility>

namespace bodyscan {

namespace {
// Spreads the low 21 bits of v so that bit i lands on bit 3i.
uint64_t spread(uint32_t v) {
  uint64_t x = v & 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffULL;
  x = (x | x << 16) & 0x1f0000ff0000ffULL;
  x = (x | x << 8) & 0x100f00f00f00f00fULL;
  x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
  x = (x | x << 2) & 0x1249249249249249ULL;
  return x;
}
}  // namespace

uint64_t morton_code(uint32_t x, uint32_t y, uint32_t z) { return spread(x) | spread(y) << 1 | spread(z) << 2; }

std::vector<uint32_t> morton_order(const std::vector<Vec3f>& points) {
  const size_t n = points.size();
  std::vector<uint32_t> order(n);
  if (n == 0) return order;
  Vec3f lo = points[0], hi = points[0];
  for (const Vec3f& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const float extent = std::max((hi - lo).maxCoeff(), 1e-30f);
  const float scale = static_cast<float>((1u << 21) - 1) / extent;
  std::vector<std::pair<uint64_t, uint32_t>> keyed(n);
  tbb::parallel_for(size_t{0}, n, [&](size_t i) {
    const Vec3f q = ((points[i] - lo) * scale).cwiseMax(0.f).cwiseMin(static_cast<float>((1u << 21) - 1));
    keyed[i] = {morton_code(static_cast<uint32_t>(q.x()), static_cast<uint32_t>(q.y()), static_cast<uint32_t>(q.z())),
                static_cast<uint32_t>(i)};
  });
  tbb::parallel_sort(keyed.begin(), keyed.end());
  for (size_t i = 0; i < n; ++i) order[i] = keyed[i].second;
  return order;
}

}  // namespace bodyscan
