#include "recon/surface/adapt_kernels.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace bodyscan {

std::vector<float> density_sigma(const NeighborGraph& graph, size_t k) {
  const size_t n = graph.k ? graph.indices.size() / graph.k : 0;
  k = std::min(k, graph.k);
  std::vector<float> sigma(n, 0.f);
  if (k == 0) return sigma;
  tbb::parallel_for(size_t{0}, n, [&](size_t i) {
    const float* d = graph.row_distances(i);
    double sum = 0.0;
    for (size_t j = 0; j < k; ++j) sum += d[j];
    sigma[i] = static_cast<float>(sum / static_cast<double>(k));
  });
  return sigma;
}

std::vector<Kernel> adapt_kernels(const std::vector<Vec3f>& points, const LocalFrames& frames,
                                  const std::vector<float>& sigma_density, const CurvatureResult* curvature,
                                  const std::vector<ShapeOperator>& shape, const std::vector<float>& confidence,
                                  const AdaptKernelsOptions& options) {
  const size_t n = points.size();
  std::vector<Kernel> kernels(n);
  std::vector<uint8_t> keep(n, 1);
  const bool sharpen = options.sharpening != 0.f && curvature != nullptr;
  tbb::parallel_for(size_t{0}, n, [&](size_t i) {
    Kernel& k = kernels[i];
    const float sd = sigma_density[i];
    const float w = confidence.empty() ? 1.f : confidence[i];
    if (!(w > 0.f) || !(sd > 0.f)) {
      keep[i] = 0;
      return;
    }
    k.center = points[i];
    k.t1 = frames.tangent1[i];
    k.t2 = frames.tangent2[i];
    k.n = frames.normals[i];
    const float base = sd * options.sigma_user;
    const float floor = options.min_sigma_fraction * base;
    k.sigma_t1 = base;
    k.sigma_t2 = base;
    if (sharpen) {
      const Eigen::Vector2f& c = curvature->curvature[i];
      k.sigma_t1 = std::max(floor, sd * (options.sigma_user - options.sharpening * c[0] * sd));
      k.sigma_t2 = std::max(floor, sd * (options.sigma_user - options.sharpening * c[1] * sd));
    }
    k.sigma_n = options.normal_scale * sd;
    if (options.curvature_compensation && !shape.empty()) {
      const ShapeOperator& s = shape[i];
      float b1 = s.s11, b2 = s.s22;
      if (k.sigma_t1 == k.sigma_t2) {
        // A round kernel turns freely: along the principal directions its
        // paraboloid is the surface's, cross term and all.
        const float theta = 0.5f * std::atan2(2.f * s.s12, s.s11 - s.s22);
        const float c = std::cos(theta), sn = std::sin(theta);
        const Vec3f t1 = c * k.t1 + sn * k.t2, t2 = c * k.t2 - sn * k.t1;
        k.t1 = t1;
        k.t2 = t2;
        b1 = c * c * s.s11 + 2.f * sn * c * s.s12 + sn * sn * s.s22;
        b2 = sn * sn * s.s11 - 2.f * sn * c * s.s12 + c * c * s.s22;
      }
      const float limit = options.max_bend / std::max(k.sigma_t1, k.sigma_t2);
      k.bend1 = std::clamp(b1, -limit, limit);
      k.bend2 = std::clamp(b2, -limit, limit);
      k.center -= (0.5f * (k.bend1 + k.bend2) * options.noise_sigma * options.noise_sigma) * k.n;
    }
    k.weight = std::min(w, 1.f);
    k.band = options.band;
  });
  size_t out = 0;
  for (size_t i = 0; i < n; ++i)
    if (keep[i]) kernels[out++] = kernels[i];
  kernels.resize(out);
  return kernels;
}

}  // namespace bodyscan
