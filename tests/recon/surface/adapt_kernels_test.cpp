#include "recon/surface/adapt_kernels.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "recon/spatial/knn_index.hpp"

namespace bodyscan {
namespace {

// A square grid of spacing h in z = 0 with frames (t1 = x, t2 = y, n = z).
struct Grid {
  std::vector<Vec3f> points;
  LocalFrames frames;
};

Grid grid(int n, float h) {
  Grid g;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) g.points.emplace_back(h * static_cast<float>(x), h * static_cast<float>(y), 0.f);
  const size_t m = g.points.size();
  g.frames.normals.assign(m, Vec3f::UnitZ());
  g.frames.tangent1.assign(m, Vec3f::UnitX());
  g.frames.tangent2.assign(m, Vec3f::UnitY());
  g.frames.eigenvalues.assign(m, Vec3f::Zero());
  return g;
}

TEST(DensitySigma, IsTheMeanDistanceToTheNearestNeighbours) {
  // Eq. 3.17 on a grid of spacing 2: an interior point's 8 nearest neighbours are
  // 4 at 2 and 4 at 2 sqrt 2, so with k = 8 the mean is 2.414; with k = 4 it is 2.
  const Grid g = grid(9, 2.f);
  const KnnIndex index(g.points);
  const NeighborGraph graph = knn_graph(index, g.points, 8);
  const size_t centre = 4 * 9 + 4;
  EXPECT_NEAR(density_sigma(graph, 8)[centre], 1.f + std::sqrt(2.f), 1e-5f);
  EXPECT_NEAR(density_sigma(graph, 4)[centre], 2.f, 1e-5f);
  // k beyond the graph's width is clamped to it.
  EXPECT_NEAR(density_sigma(graph, 50)[centre], 1.f + std::sqrt(2.f), 1e-5f);
}

TEST(AdaptKernels, SizesFollowDensityAndSharpeningShrinksAlongTheBend) {
  const Grid g = grid(5, 1.f);
  const size_t n = g.points.size();
  std::vector<float> sd(n, 2.f);
  sd[1] = 4.f;
  AdaptKernelsOptions o;
  o.sigma_user = 1.5f;
  o.normal_scale = 0.5f;
  o.curvature_compensation = false;
  std::vector<Kernel> k = adapt_kernels(g.points, g.frames, sd, nullptr, {}, {}, o);
  ASSERT_EQ(k.size(), n);
  EXPECT_FLOAT_EQ(k[0].sigma_t1, 3.f);  // eq. 3.18: sigma_user * sigma_density
  EXPECT_FLOAT_EQ(k[0].sigma_t2, 3.f);
  EXPECT_FLOAT_EQ(k[0].sigma_n, 1.f);
  EXPECT_FLOAT_EQ(k[1].sigma_t1, 6.f);
  EXPECT_FLOAT_EQ(k[0].bend1, 0.f);
  EXPECT_FLOAT_EQ(k[0].bend2, 0.f);

  // Eq. 3.24 (scale-free): sigma = sd (sigma_user - s c sd), c the section's
  // curvature; floored at min_sigma_fraction of the unsharpened size.
  CurvatureResult c;
  c.curvature.assign(n, Eigen::Vector2f(0.1f, 0.f));
  c.curvature[2] = Eigen::Vector2f(10.f, 0.f);
  o.sharpening = 2.f;
  k = adapt_kernels(g.points, g.frames, sd, &c, {}, {}, o);
  EXPECT_FLOAT_EQ(k[0].sigma_t1, 2.f * (1.5f - 2.f * 0.1f * 2.f));  // 2.2
  EXPECT_FLOAT_EQ(k[0].sigma_t2, 3.f);                              // flat direction unchanged
  EXPECT_FLOAT_EQ(k[2].sigma_t1, 0.25f * 3.f);                      // the floor
}

TEST(AdaptKernels, ConfidenceWeightsAndDropsPoints) {
  const Grid g = grid(3, 1.f);
  const size_t n = g.points.size();
  std::vector<float> conf(n, 0.5f);
  conf[0] = 0.f;
  conf[1] = 3.f;
  AdaptKernelsOptions o;
  const std::vector<Kernel> k = adapt_kernels(g.points, g.frames, std::vector<float>(n, 1.f), nullptr, {}, conf, o);
  ASSERT_EQ(k.size(), n - 1);  // confidence 0 takes no part
  EXPECT_EQ(k[0].center, g.points[1]);
  EXPECT_FLOAT_EQ(k[0].weight, 1.f);  // clamped to 1
  EXPECT_FLOAT_EQ(k[1].weight, 0.5f);
}

TEST(AdaptKernels, BendIsClampedAndNoiseBiasRemovedAlongTheNormal) {
  const Grid g = grid(3, 1.f);
  const size_t n = g.points.size();
  std::vector<ShapeOperator> h(n, ShapeOperator{0.2f, 0.f, 0.2f});
  h[1] = {50.f, 0.f, 50.f};  // far beyond max_bend / sigma_t
  h[2] = {-50.f, 0.f, -50.f};
  AdaptKernelsOptions o;
  o.sigma_user = 1.f;
  o.max_bend = 0.7f;
  o.noise_sigma = 0.5f;
  const std::vector<Kernel> k = adapt_kernels(g.points, g.frames, std::vector<float>(n, 2.f), nullptr, h, {}, o);
  EXPECT_FLOAT_EQ(k[0].bend1, 0.2f);
  EXPECT_FLOAT_EQ(k[0].bend2, 0.2f);
  EXPECT_FLOAT_EQ(k[1].bend1, 0.35f);  // 0.7 / sigma_t (2)
  EXPECT_FLOAT_EQ(k[2].bend2, -0.35f);
  // Noise of 0.5 on a surface of mean curvature 0.2 puts points 0.2 * 0.25 = 0.05
  // outside it on average: the kernel moves back along -n by that much.
  EXPECT_NEAR(k[0].center.z(), -0.05f, 1e-6f);
  EXPECT_NEAR(k[0].center.x(), g.points[0].x(), 1e-6f);
  EXPECT_NEAR(k[2].center.z(), 0.35f * 0.25f, 1e-6f);  // concave: moved outward
  // Without curvature compensation nothing moves.
  o.curvature_compensation = false;
  const std::vector<Kernel> flat = adapt_kernels(g.points, g.frames, std::vector<float>(n, 2.f), nullptr, h, {}, o);
  EXPECT_EQ(flat[0].center, g.points[0]);
}

TEST(AdaptKernels, ARoundKernelBendsAlongThePrincipalDirections) {
  // A cylinder of radius 5 along (1, 1, 0) / sqrt 2 seen in a frame at 45 degrees
  // to it: S = [[0.1, -0.1], [-0.1, 0.1]] in (t1, t2) = (x, y). The kernel turns
  // its axes onto the cylinder's (one of them across it, bend 1/5; the other along
  // it, bend 0), and its mean bend, which sets the noise shift, stays 0.1.
  const Grid g = grid(3, 1.f);
  const size_t n = g.points.size();
  std::vector<ShapeOperator> s(n, ShapeOperator{0.1f, -0.1f, 0.1f});
  AdaptKernelsOptions o;
  o.sigma_user = 1.f;
  o.noise_sigma = 0.5f;
  const std::vector<Kernel> k = adapt_kernels(g.points, g.frames, std::vector<float>(n, 2.f), nullptr, s, {}, o);
  const Vec3f along = Vec3f(1, 1, 0).normalized(), across = Vec3f(1, -1, 0).normalized();
  const Kernel& k0 = k[0];
  const Vec3f& bent_axis = std::abs(k0.bend1) > std::abs(k0.bend2) ? k0.t1 : k0.t2;
  const Vec3f& flat_axis = std::abs(k0.bend1) > std::abs(k0.bend2) ? k0.t2 : k0.t1;
  EXPECT_NEAR(std::max(k0.bend1, k0.bend2), 0.2f, 1e-6f);
  EXPECT_NEAR(std::min(k0.bend1, k0.bend2), 0.f, 1e-6f);
  EXPECT_NEAR(std::abs(bent_axis.dot(across)), 1.f, 1e-6f);
  EXPECT_NEAR(std::abs(flat_axis.dot(along)), 1.f, 1e-6f);
  EXPECT_NEAR(k0.t1.cross(k0.t2).dot(k0.n), 1.f, 1e-6f);  // still right-handed
  EXPECT_NEAR(k0.center.z(), -0.1f * 0.25f, 1e-6f);

  // A kernel sharpened along its own axes keeps them, and bends by the normal
  // curvatures along them.
  CurvatureResult c;
  c.curvature.assign(n, Eigen::Vector2f(0.1f, 0.f));
  o.sharpening = 1.f;
  const std::vector<Kernel> sharp = adapt_kernels(g.points, g.frames, std::vector<float>(n, 2.f), &c, s, {}, o);
  EXPECT_EQ(sharp[0].t1, g.frames.tangent1[0]);
  EXPECT_FLOAT_EQ(sharp[0].bend1, 0.1f);
  EXPECT_FLOAT_EQ(sharp[0].bend2, 0.1f);
}

}  // namespace
}  // namespace bodyscan
