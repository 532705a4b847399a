// Noise estimation against clouds with a known Gaussian noise level.
#include "recon/surface/estimate_noise.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "recon/geometry/sample_surface.hpp"

namespace bodyscan {
namespace {

double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// Runs the estimator as reconstruct_surface() does: graph of 30, PCA over 20.
NoiseEstimate estimate(const std::vector<Vec3f>& pts) {
  const KnnIndex index(pts);
  const NeighborGraph g = knn_graph(index, pts, 30);
  const LocalFrames f = estimate_normals(pts, index, g, {.k = 20});
  return estimate_noise(pts, index, g, f);
}

double brute_median_spacing(const std::vector<Vec3f>& pts) {
  std::vector<double> nn(pts.size(), 1e300);
  for (size_t i = 0; i < pts.size(); ++i)
    for (size_t j = 0; j < pts.size(); ++j)
      if (i != j) nn[i] = std::min(nn[i], (pts[i].cast<double>() - pts[j].cast<double>()).norm());
  std::nth_element(nn.begin(), nn.begin() + nn.size() / 2, nn.end());
  return nn[nn.size() / 2];
}

// 4000 points on a sphere of radius 10 (spacing ~0.56) and on a 40 x 40 square
// (random, median spacing ~0.35); noise as a fraction of each cloud's noise-free
// median spacing.
PointCloud sphere_cloud() { return fibonacci_sphere(4000, 10.0); }
PointCloud plane_cloud() {
  std::mt19937_64 rng(17);
  PointCloud c;
  for (int i = 0; i < 4000; ++i)
    c.positions.emplace_back(40.f * static_cast<float>(uniform01(rng)), 40.f * static_cast<float>(uniform01(rng)), 0.f);
  return c;
}

struct NoiseCase {
  const char* surface;
  double noise_in_spacings;
};

class EstimateNoiseLevels : public ::testing::TestWithParam<NoiseCase> {};

TEST_P(EstimateNoiseLevels, WithinFifteenPercentOfTruth) {
  const NoiseCase nc = GetParam();
  PointCloud c = std::string(nc.surface) == "sphere" ? sphere_cloud() : plane_cloud();
  const NoiseEstimate clean = estimate(c.positions);
  const double spacing = clean.median_spacing;
  ASSERT_GT(spacing, 0.0);
  const double sigma = nc.noise_in_spacings * spacing;
  add_gaussian_noise(c, sigma, 23);
  const NoiseEstimate est = estimate(c.positions);
  EXPECT_NEAR(est.sigma, sigma, 0.15 * sigma) << nc.surface << " noise " << nc.noise_in_spacings << " spacings";
  EXPECT_EQ(est.samples, c.size());  // fewer than max_samples: every point
}

INSTANTIATE_TEST_SUITE_P(Levels, EstimateNoiseLevels,
                         ::testing::Values(NoiseCase{"sphere", 0.05}, NoiseCase{"sphere", 0.2},
                                           NoiseCase{"sphere", 0.5}, NoiseCase{"plane", 0.05}, NoiseCase{"plane", 0.2},
                                           NoiseCase{"plane", 0.5}),
                         [](const ::testing::TestParamInfo<NoiseCase>& param_info) {
                           return std::string(param_info.param.surface) + "_" +
                                  std::to_string(static_cast<int>(param_info.param.noise_in_spacings * 100)) + "pct";
                         });

TEST(EstimateNoise, NoiseFreeIsNearZero) {
  for (const PointCloud& c : {sphere_cloud(), plane_cloud()}) {
    const NoiseEstimate est = estimate(c.positions);
    EXPECT_LT(est.sigma, 0.05f * est.median_spacing);
    EXPECT_GE(est.sigma, 0.f);
  }
}

TEST(EstimateNoise, NoiseFreeCubeIsNearZero) {
  // A noise-free cube [-1, 1]^3, 6000 area-uniform points (median nearest-neighbour
  // spacing 0.03): most
  // points lie on flat faces, and the median of the fits is meant to be "robust to
  // edges" (estimate_noise.hpp).
  TriangleMesh cube;
  for (int i = 0; i < 8; ++i)
    cube.vertices.emplace_back(2 * (i & 1) - 1, 2 * ((i >> 1) & 1) - 1, 2 * ((i >> 2) & 1) - 1);
  cube.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                    {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  const PointCloud c = sample_mesh_uniform(cube, 6000, 13, false);
  const KnnIndex index(c.positions);
  const NeighborGraph g = knn_graph(index, c.positions, 30);
  const LocalFrames f = estimate_normals(c.positions, index, g, {.k = 20});
  // The first fit (k = 20) alone sees the faces as flat.
  const NoiseEstimate narrow = estimate_noise(c.positions, index, g, f, {.max_k = 20});
  EXPECT_LT(narrow.sigma, 0.05f * narrow.median_spacing);
  const NoiseEstimate est = estimate_noise(c.positions, index, g, f);
  EXPECT_LT(est.sigma, 0.05f * est.median_spacing);
}

TEST(EstimateNoise, MedianSpacingIsTheNearestNeighbourMedian) {
  const PointCloud c = plane_cloud();
  const NoiseEstimate est = estimate(c.positions);
  // With 4000 samples the median is an order statistic of the same distances.
  EXPECT_NEAR(est.median_spacing, brute_median_spacing(c.positions), 1e-5 * est.median_spacing);
}

TEST(EstimateNoise, ScaleInvariant) {
  // The same cloud in mm and in m: sigma scales with the unit.
  PointCloud mm = sphere_cloud();
  add_gaussian_noise(mm, 0.1, 29);
  PointCloud m = mm;
  for (Vec3f& p : m.positions) p *= 1e-3f;
  const NoiseEstimate a = estimate(mm.positions), b = estimate(m.positions);
  EXPECT_NEAR(b.sigma * 1e3, a.sigma, 1e-3 * a.sigma);
  EXPECT_NEAR(b.median_spacing * 1e3, a.median_spacing, 1e-3 * a.median_spacing);
}

TEST(EstimateNoise, SampleStrideAndTinyClouds) {
  PointCloud c = sphere_cloud();
  add_gaussian_noise(c, 0.1, 31);
  const KnnIndex index(c.positions);
  const NeighborGraph g = knn_graph(index, c.positions, 30);
  const LocalFrames f = estimate_normals(c.positions, index, g, {.k = 20});
  const NoiseEstimate part = estimate_noise(c.positions, index, g, f, {.max_samples = 500});
  EXPECT_EQ(part.samples, 500u);
  EXPECT_NEAR(part.sigma, 0.1, 0.015);

  // Fewer than 8 points: nothing to estimate.
  const std::vector<Vec3f> few = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 0, 0}};
  const KnnIndex fi(few);
  const NeighborGraph fg = knn_graph(fi, few, 4);
  const LocalFrames ff = estimate_normals(few, fi, fg, {.k = 4});
  const NoiseEstimate none = estimate_noise(few, fi, fg, ff);
  EXPECT_EQ(none.sigma, 0.f);
  EXPECT_EQ(none.samples, 0u);
}

}  // namespace
}  // namespace bodyscan
