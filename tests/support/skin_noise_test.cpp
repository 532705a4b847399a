#include "tests/support/skin_noise.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/test_meshes.hpp"

namespace bodyscan {
namespace {

// The displacement of each vertex along its (outward) radius.
std::vector<double> radial_moves(const TriangleMesh& before, const TriangleMesh& after) {
  std::vector<double> d;
  for (size_t i = 0; i < before.vertices.size(); ++i) d.push_back(after.vertices[i].norm() - before.vertices[i].norm());
  return d;
}

TEST(SkinNoise, MovesTheSkinAlongItsNormalsByTheRmsAskedSmoothlyAndRepeatably) {
  const TriangleMesh sphere = testing::icosphere(6, 150);  // vertices about 2.5 mm apart
  const TriangleMesh a = with_smooth_skin_noise(sphere, 0.25, 1, {40});
  const std::vector<double> d = radial_moves(sphere, a);
  double ss = 0;
  for (double x : d) ss += x * x;
  EXPECT_NEAR(std::sqrt(ss / d.size()), 0.25, 0.005);  // along the normals: all of it radial
  // Smooth: neighbours a few mm apart move nearly alike (a 40 mm field changes by
  // an eighth of its RMS over one edge here), where white noise would not.
  double edge_ss = 0;
  size_t edges = 0;
  for (const auto& t : sphere.triangles)
    for (int e = 0; e < 3; ++e) edge_ss += std::pow(d[t[e]] - d[t[(e + 1) % 3]], 2), ++edges;
  EXPECT_LT(std::sqrt(edge_ss / edges), 0.2 * 0.25);  // white noise: 1.4 times the RMS
  // The same seed, the same skin; another seed, another.
  const TriangleMesh again = with_smooth_skin_noise(sphere, 0.25, 1, {40});
  EXPECT_EQ(again.vertices, a.vertices);
  const std::vector<double> other = radial_moves(sphere, with_smooth_skin_noise(sphere, 0.25, 2, {40}));
  double diff = 0;
  for (size_t i = 0; i < d.size(); ++i) diff += std::pow(d[i] - other[i], 2);
  EXPECT_GT(std::sqrt(diff / d.size()), 0.2);
  // Two scales add: each is scaled to the RMS on its own.
  const std::vector<double> both = radial_moves(sphere, with_smooth_skin_noise(sphere, 0.25, 1, {40, 10}));
  double bs = 0;
  for (double x : both) bs += x * x;
  EXPECT_NEAR(std::sqrt(bs / both.size()), 0.25 * std::sqrt(2.0), 0.06);
}

}  // namespace
}  // namespace bodyscan
