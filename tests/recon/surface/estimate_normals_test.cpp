// PCA frames on surfaces with known normals: planes, spheres, and a neighbourhood
// whose covariance is known in closed form.
#include "recon/surface/estimate_normals.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "recon/geometry/sample_surface.hpp"

namespace bodyscan {
namespace {

double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// n points uniformly in [0, size]^2 on the plane z = z0, offset by `offset` in x and y.
PointCloud random_plane(size_t n, float size, float z0, float offset, uint64_t seed) {
  std::mt19937_64 rng(seed);
  PointCloud c;
  for (size_t i = 0; i < n; ++i) {
    c.positions.emplace_back(offset + size * static_cast<float>(uniform01(rng)),
                             offset + size * static_cast<float>(uniform01(rng)), z0);
  }
  return c;
}

// Angle between the lines of a and b (sign ignored), radians.
double line_angle(const Vec3f& a, const Vec3f& b) {
  const double c = std::abs(a.cast<double>().normalized().dot(b.cast<double>().normalized()));
  // acos is ill-conditioned near 1; the cross product is not.
  return std::atan2(a.cast<double>().normalized().cross(b.cast<double>().normalized()).norm(), c);
}

// Every frame orthonormal and right-handed: (t1, t2, n) = rotation; eigenvalues
// non-negative and ascending.
void expect_valid_frames(const LocalFrames& f, size_t n) {
  ASSERT_EQ(f.normals.size(), n);
  ASSERT_EQ(f.tangent1.size(), n);
  ASSERT_EQ(f.tangent2.size(), n);
  ASSERT_EQ(f.eigenvalues.size(), n);
  for (size_t i = 0; i < n; ++i) {
    const Vec3f &t1 = f.tangent1[i], &t2 = f.tangent2[i], &nr = f.normals[i];
    ASSERT_NEAR(t1.norm(), 1.f, 1e-5f) << i;
    ASSERT_NEAR(t2.norm(), 1.f, 1e-5f) << i;
    ASSERT_NEAR(nr.norm(), 1.f, 1e-5f) << i;
    ASSERT_NEAR(t1.dot(t2), 0.f, 1e-5f) << i;
    ASSERT_NEAR(t1.dot(nr), 0.f, 1e-5f) << i;
    ASSERT_NEAR(t2.dot(nr), 0.f, 1e-5f) << i;
    ASSERT_LT((t1.cross(t2) - nr).norm(), 1e-5f) << "left-handed frame at " << i;
    const Vec3f& ev = f.eigenvalues[i];
    ASSERT_GE(ev[0], 0.f) << i;
    ASSERT_LE(ev[0], ev[1]) << i;
    ASSERT_LE(ev[1], ev[2]) << i;
  }
}

TEST(EstimateNormals, KnownCovarianceGivesExactFrameAndEigenvalues) {
  // Point 0 and its six neighbours (±2, 0, 0), (0, ±1, 0), (0, 0, ±0.5): the seven
  // points have mean 0 and covariance diag(8, 2, 0.5) / 7, so at point 0 the
  // eigenvalues are (0.5, 2, 8) / 7, tangent1 = ±x, tangent2 = ±y, normal = ±z.
  const std::vector<Vec3f> pts = {{0, 0, 0}, {2, 0, 0}, {-2, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 0.5f}, {0, 0, -0.5f}};
  const KnnIndex index(pts);
  for (size_t graph_k : {size_t{6}, size_t{2}}) {  // from the graph, then from the index
    const NeighborGraph graph = knn_graph(index, pts, graph_k);
    const LocalFrames f = estimate_normals(pts, index, graph, {.k = 6});
    expect_valid_frames(f, pts.size());
    EXPECT_NEAR(f.eigenvalues[0][0], 0.5 / 7, 1e-6) << "graph k " << graph_k;
    EXPECT_NEAR(f.eigenvalues[0][1], 2.0 / 7, 1e-6);
    EXPECT_NEAR(f.eigenvalues[0][2], 8.0 / 7, 1e-6);
    EXPECT_NEAR(std::abs(f.normals[0].z()), 1.f, 1e-6f);
    EXPECT_NEAR(std::abs(f.tangent1[0].x()), 1.f, 1e-6f);
    EXPECT_NEAR(std::abs(f.tangent2[0].y()), 1.f, 1e-6f);
  }
}

TEST(EstimateNormals, NoiseFreePlaneFarFromOrigin) {
  // z = 1000 is exact in float, so the normals must be exact up to the PCA's own
  // rounding although the points sit 1000 units from the origin (the covariance is
  // centred on each point first).
  const PointCloud c = random_plane(3000, 50.f, 1000.f, 1000.f, 7);
  const KnnIndex index(c.positions);
  const NeighborGraph graph = knn_graph(index, c.positions, 20);
  const LocalFrames f = estimate_normals(c.positions, index, graph);
  expect_valid_frames(f, c.size());
  double worst = 0;
  for (size_t i = 0; i < c.size(); ++i) worst = std::max(worst, line_angle(f.normals[i], Vec3f::UnitZ()));
  EXPECT_LT(worst, 1e-4) << "radians";
  for (size_t i = 0; i < c.size(); ++i) {
    EXPECT_LT(f.eigenvalues[i][0], 1e-10f * f.eigenvalues[i][2]) << i;  // flat: no spread along n
  }
}

TEST(EstimateNormals, TiltedNoisyPlaneWithinFewDegrees) {
  // Unit spacing-ish plane (3000 points on 50 x 50: spacing ~0.9), noise 0.05 per
  // axis, rotated so the normal is not an axis. PCA over 21 points spread ~2 units
  // sees a tilt of about sigma / spread / sqrt(k) ~ 0.5 degrees; allow 3 degrees
  // at the 99th percentile and 6 at the worst point.
  PointCloud c = random_plane(3000, 50.f, 0.f, 0.f, 8);
  const Eigen::Matrix3f rot = (Eigen::AngleAxisf(0.7f, Vec3f(1, 2, 3).normalized())).toRotationMatrix();
  for (Vec3f& p : c.positions) p = rot * p;
  add_gaussian_noise(c, 0.05, 9);
  const Vec3f truth = rot * Vec3f::UnitZ();
  const KnnIndex index(c.positions);
  const NeighborGraph graph = knn_graph(index, c.positions, 20);
  const LocalFrames f = estimate_normals(c.positions, index, graph);
  expect_valid_frames(f, c.size());
  std::vector<double> err(c.size());
  for (size_t i = 0; i < c.size(); ++i) err[i] = line_angle(f.normals[i], truth);
  std::sort(err.begin(), err.end());
  const double deg = std::numbers::pi / 180;
  EXPECT_LT(err[err.size() * 99 / 100], 3 * deg);
  EXPECT_LT(err.back(), 6 * deg);
  // A noisy plane spreads along its normal by about the noise variance (PCA takes
  // the direction of least spread, so a little less).
  std::vector<float> l0(c.size());
  for (size_t i = 0; i < c.size(); ++i) l0[i] = f.eigenvalues[i][0];
  std::nth_element(l0.begin(), l0.begin() + l0.size() / 2, l0.end());
  EXPECT_GT(l0[l0.size() / 2], 0.3f * 0.05f * 0.05f);
  EXPECT_LT(l0[l0.size() / 2], 1.1f * 0.05f * 0.05f);
}

TEST(EstimateNormals, SphereNormalsAreRadial) {
  const PointCloud c = fibonacci_sphere(2000, 3.0);
  const KnnIndex index(c.positions);
  const NeighborGraph graph = knn_graph(index, c.positions, 20);
  const LocalFrames f = estimate_normals(c.positions, index, graph);
  expect_valid_frames(f, c.size());
  for (size_t i = 0; i < c.size(); ++i) {
    EXPECT_GT(std::abs(f.normals[i].dot(c.positions[i].normalized())), 0.999f) << i;
  }
  // On a sphere the two tangential spreads are about equal and the normal one small:
  // the neighbourhood (radius ~ 2.5 spacings) sags by r^2 / 2R against its width r.
  for (size_t i = 0; i < c.size(); ++i) {
    EXPECT_LT(f.eigenvalues[i][0], 0.01f * f.eigenvalues[i][1]) << i;
  }
}

TEST(EstimateNormals, GraphAndIndexNeighbourhoodsAgree) {
  // The same k either from the graph or queried from the index: same neighbours,
  // so the same frames up to sign.
  const PointCloud c = fibonacci_sphere(1500, 1.0);
  const KnnIndex index(c.positions);
  const NeighborGraph wide = knn_graph(index, c.positions, 15);
  const NeighborGraph narrow = knn_graph(index, c.positions, 5);
  const LocalFrames a = estimate_normals(c.positions, index, wide, {.k = 15});
  const LocalFrames b = estimate_normals(c.positions, index, narrow, {.k = 15});
  for (size_t i = 0; i < c.size(); ++i) {
    EXPECT_LT(line_angle(a.normals[i], b.normals[i]), 1e-5) << i;
    EXPECT_LT((a.eigenvalues[i] - b.eigenvalues[i]).norm(), 1e-6f * a.eigenvalues[i][2] + 1e-12f) << i;
  }
}

TEST(EstimateNormals, FlipFrameKeepsRightHandedness) {
  const PointCloud c = fibonacci_sphere(200, 1.0);
  const KnnIndex index(c.positions);
  const NeighborGraph graph = knn_graph(index, c.positions, 20);
  LocalFrames f = estimate_normals(c.positions, index, graph);
  const LocalFrames before = f;
  for (size_t i = 0; i < c.size(); i += 2) flip_frame(f, i);
  expect_valid_frames(f, c.size());
  for (size_t i = 0; i < c.size(); ++i) {
    const float s = i % 2 == 0 ? -1.f : 1.f;
    EXPECT_EQ(f.normals[i], (s * before.normals[i]).eval());
    EXPECT_EQ(f.tangent1[i], before.tangent1[i]);  // the principal direction stays
    EXPECT_EQ(f.eigenvalues[i], before.eigenvalues[i]);
  }
}

}  // namespace
}  // namespace bodyscan
