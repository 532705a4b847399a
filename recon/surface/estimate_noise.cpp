#include "recon/surface/estimate_noise.hpp"

#include "core/median.hpp"
#include "recon/surface/estimate_curvature.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace bodyscan {

NoiseEstimate estimate_noise(const std::vector<Vec3f>& points, const KnnIndex& index, const NeighborGraph& graph,
                             const LocalFrames& frames, const EstimateNoiseOptions& options) {
  NoiseEstimate est;
  const size_t n = points.size();
  if (n < 8 || graph.k == 0) return est;
  const size_t samples = std::min(n, options.max_samples);
  const double stride = static_cast<double>(n) / static_cast<double>(samples);
  auto sample_index = [&](size_t s) { return std::min(n - 1, static_cast<size_t>(static_cast<double>(s) * stride)); };
  std::vector<float> spacing(samples);
  for (size_t s = 0; s < samples; ++s) spacing[s] = graph.row_distances(sample_index(s))[0];
  est.median_spacing = median_in_place(spacing);
  est.samples = samples;

  // A quadric needs well over six points, and a fit wider than a fraction of the
  // cloud no longer sees a height field.
  const size_t widest = std::min(options.max_k, n / 8);
  std::vector<float> residual(samples);
  for (size_t k = std::min(options.k, n - 1); k >= 12; k *= 2) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, samples, 64), [&](const tbb::blocked_range<size_t>& r) {
      std::vector<uint32_t> idx(k + 1);
      std::vector<float> d2(k + 1);
      for (size_t s = r.begin(); s != r.end(); ++s) {
        const size_t i = sample_index(s);
        const size_t got = index.knn(points[i], k + 1, idx.data(), d2.data());
        size_t m = 0;
        for (size_t j = 0; j < got; ++j)
          if (idx[j] != i) idx[m++] = idx[j];
        const LocalQuadric q = fit_local_quadric(points, i, idx.data(), std::min(m, k), frames);
        residual[s] = q.ok ? static_cast<float>(q.residual_rms) : 0.f;
      }
    });
    const float sigma = median_in_place(residual);
    const bool settled = k > options.k && sigma <= 1.1f * est.sigma;
    est.sigma = std::max(est.sigma, sigma);
    // Noise well below the spacing is fully seen by the first fit; only noise that
    // rivals the spacing hides in a narrow one. Widening a fit on clean data only
    // bends it over edges and corners.
    const bool small = est.sigma < 0.3f * est.median_spacing;
    if (settled || small || 2 * k > widest) break;
  }
  return est;
}

}  // namespace bodyscan
