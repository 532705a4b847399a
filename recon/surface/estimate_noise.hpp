// Estimates the noise of a scanned surface from the points alone, so the
// reconstruction's defaults can adapt to it (thesis §3.2.2.2: sigma_n "must be
// adjusted based on the noise in the point cloud in the normal direction").
//
// For a sample of points, a quadric height field h = a u^2 + b uv + c v^2 + d u + e v + f
// is fitted to the point and its k neighbours in the point's PCA frame; the residual
// RMS, corrected for the six fitted parameters, measures the scatter across the
// surface that curvature does not explain. The median over the sample is robust to
// edges and outliers. When the noise is not small against the spacing, a fit over
// k neighbours absorbs part of it, so the fit is widened (k doubled, up to
// max_k) until the estimate stops growing.
#pragma once

#include <cstdint>
#include <vector>

#include "recon/geometry/point_cloud.hpp"
#include "recon/spatial/knn_index.hpp"
#include "recon/surface/estimate_normals.hpp"

namespace bodyscan {

struct EstimateNoiseOptions {
  size_t k = 20;               // neighbours of the first fit
  size_t max_k = 160;          // widest fit
  size_t max_samples = 20000;  // points fitted (evenly strided over the cloud)
};

struct NoiseEstimate {
  float sigma = 0.f;           // per-axis noise standard deviation, the points' unit
  float median_spacing = 0.f;  // median distance to the nearest neighbour
  size_t samples = 0;
};

NoiseEstimate estimate_noise(const std::vector<Vec3f>& points, const KnnIndex& index, const NeighborGraph& graph,
                             const LocalFrames& frames, const EstimateNoiseOptions& options = {});

}  // namespace bodyscan
