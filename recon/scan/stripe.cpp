#include "recon/scan/stripe.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>

namespace bodyscan {

namespace {

// max over the row of (f - b) saturated at 0. Plain loop with unsigned arithmetic
// that GCC turns into saturating vector subtracts and maxima.
__attribute__((always_inline)) inline uint16_t chunk_peak(const uint16_t* __restrict f, const uint16_t* __restrict b,
                                                          int n) {
  uint16_t m = 0;
  for (int i = 0; i < n; ++i) {
    const uint16_t d = f[i] > b[i] ? static_cast<uint16_t>(f[i] - b[i]) : 0;
    m = d > m ? d : m;
  }
  return m;
}

// The row's maximum chunk by chunk (each a vectorised pass over 64 pixels), and the
// first chunk holding it, so that the brightest pixel is then looked for there only.
constexpr int kChunk = 64;
// Cloned for x86-64-v3 (AVX2), chosen by the CPU's features (implicit_field.cpp).
__attribute__((target_clones("arch=x86-64-v3", "default"))) uint16_t row_peak(const uint16_t* __restrict f,
                                                                              const uint16_t* __restrict b, int n,
                                                                              int* chunk) {
  uint16_t peak = 0;
  *chunk = 0;
  int c = 0;
  for (; c + kChunk <= n; c += kChunk) {
    const uint16_t m = chunk_peak(f + c, b + c, kChunk);
    if (m > peak) peak = m, *chunk = c;
  }
  if (c < n) {
    const uint16_t m = chunk_peak(f + c, b + c, n - c);
    if (m > peak) peak = m, *chunk = c;
  }
  return peak;
}

}  // namespace

StatusOr<std::vector<StripeSample>> extract_stripe(const ImageView& frame, const ImageView& base,
                                                   const StripeOptions& options, int full_scale,
                                                   const std::vector<ColumnRange>* windows) {
  if (frame.width != base.width || frame.height != base.height) {
    return invalid_argument("stripe extraction: the frame is " + std::to_string(frame.width) + "x" +
                            std::to_string(frame.height) + " but the base frame is " + std::to_string(base.width) +
                            "x" + std::to_string(base.height));
  }
  if (frame.width <= 0 || frame.height <= 0 || !frame.pixels || !base.pixels) {
    return invalid_argument("stripe extraction: empty image");
  }
  if (options.radius < 0 || options.radius > 64 || options.threshold < 1) {
    return invalid_argument("stripe extraction: radius must be 0..64 and threshold at least 1");
  }
  if (windows && windows->size() != static_cast<size_t>(frame.height)) {
    return invalid_argument("stripe extraction: " + std::to_string(windows->size()) + " row windows for " +
                            std::to_string(frame.height) + " rows");
  }
  const int w = frame.width, r = options.radius;
  std::vector<StripeSample> per_row(static_cast<size_t>(frame.height));
  std::vector<uint8_t> found(static_cast<size_t>(frame.height), 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, frame.height, 16), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y) {
      const uint16_t* f = frame.row(y);
      const uint16_t* b = base.row(y);
      int lo = 0, hi = w;
      if (windows) {
        lo = std::max(0, (*windows)[static_cast<size_t>(y)].begin);
        hi = std::min(w, (*windows)[static_cast<size_t>(y)].end);
        if (hi <= lo) continue;
      }
      int chunk = 0;
      const uint16_t peak = row_peak(f + lo, b + lo, hi - lo, &chunk);
      if (peak < options.threshold) continue;
      int x0 = lo + chunk;
      while (!(f[x0] > b[x0] && f[x0] - b[x0] == peak)) ++x0;  // the first brightest pixel
      double sw = 0, sx = 0;
      bool saturated = false;
      for (int x = std::max(lo, x0 - r); x <= std::min(hi - 1, x0 + r); ++x) {
        const int d = f[x] > b[x] ? f[x] - b[x] : 0;
        sw += d;
        sx += static_cast<double>(d) * x;
        saturated = saturated || f[x] >= full_scale;
      }
      per_row[static_cast<size_t>(y)] = {y, static_cast<float>(sx / sw), peak, saturated};
      found[static_cast<size_t>(y)] = 1;
    }
  });
  std::vector<StripeSample> out;
  for (int y = 0; y < frame.height; ++y)
    if (found[static_cast<size_t>(y)]) out.push_back(per_row[static_cast<size_t>(y)]);
  return out;
}

void smooth_stripe(std::vector<StripeSample>& samples, int half_window, double max_step) {
  const size_t n = samples.size();
  std::vector<float> out(n);
  for (size_t i = 0; i < n; ++i) {
    out[i] = samples[i].column;
    // Walk out from sample i each way while the stripe continues; the sums of a
    // least-squares parabola in dr = row - row_i (the column relative to sample i's).
    const double c0 = samples[i].column;
    double s0 = 1, s1 = 0, s2 = 0, s3 = 0, s4 = 0, t0 = 0, t1 = 0, t2 = 0;
    int below = 0, above = 0;
    for (int dir : {-1, 1}) {
      size_t prev = i;
      for (long j = static_cast<long>(i) + dir; j >= 0 && j < static_cast<long>(n); j += dir) {
        const StripeSample& a = samples[static_cast<size_t>(j)];
        const int dr = a.row - samples[i].row;
        if (std::abs(dr) > half_window) break;
        const int step = std::abs(a.row - samples[prev].row);
        if (std::abs(a.column - samples[prev].column) > max_step * step) break;
        const double r = dr, r2 = r * r, c = a.column - c0;
        s0 += 1, s1 += r, s2 += r2, s3 += r2 * r, s4 += r2 * r2;
        t0 += c, t1 += r * c, t2 += r2 * c;
        (dir < 0 ? below : above) += 1;
        prev = static_cast<size_t>(j);
      }
    }
    if (s0 < 3) continue;
    if (below >= 2 && above >= 2) {
      // The parabola's value at dr = 0 (Cramer's rule on the 3x3 normal equations).
      const double det = s0 * (s2 * s4 - s3 * s3) - s1 * (s1 * s4 - s2 * s3) + s2 * (s1 * s3 - s2 * s2);
      if (std::abs(det) > 1e-9) {
        const double num = t0 * (s2 * s4 - s3 * s3) - s1 * (t1 * s4 - s3 * t2) + s2 * (t1 * s3 - s2 * t2);
        out[i] = static_cast<float>(c0 + num / det);
        continue;
      }
    }
    // Too near an end of the stripe for a parabola: a straight line.
    const double det = s0 * s2 - s1 * s1;
    if (det <= 0) continue;
    out[i] = static_cast<float>(c0 + (t0 * s2 - s1 * t1) / det);
  }
  for (size_t i = 0; i < n; ++i) samples[i].column = out[i];
}

size_t drop_short_runs(std::vector<StripeSample>& samples, int min_rows, double max_step) {
  if (min_rows <= 1) return 0;
  const size_t n = samples.size();
  std::vector<uint8_t> keep(n, 1);
  size_t begin = 0;
  for (size_t i = 1; i <= n; ++i) {
    if (i < n && samples[i].row - samples[i - 1].row == 1 &&
        std::abs(samples[i].column - samples[i - 1].column) <= max_step)
      continue;
    if (i - begin < static_cast<size_t>(min_rows)) std::fill(keep.begin() + begin, keep.begin() + i, 0);
    begin = i;
  }
  size_t out = 0;
  for (size_t i = 0; i < n; ++i)
    if (keep[i]) samples[out++] = samples[i];
  samples.resize(out);
  return n - out;
}

}  // namespace bodyscan
