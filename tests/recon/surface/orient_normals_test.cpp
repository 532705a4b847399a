// Normal orientation: spanning-tree propagation on closed shapes with known outward
// normals, and orientation toward the cameras that saw each point.
#include "recon/surface/orient_normals.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "recon/geometry/sample_surface.hpp"
#include "recon/io/ply.hpp"
#include "tests/test_data.hpp"

namespace bodyscan {
namespace {

// PCA frames with every normal's sign then randomised, so that orientation has to
// be recovered from scratch.
LocalFrames scrambled_frames(const std::vector<Vec3f>& pts, const KnnIndex& index, const NeighborGraph& graph,
                             uint64_t seed) {
  LocalFrames f = estimate_normals(pts, index, graph);
  std::mt19937_64 rng(seed);
  for (size_t i = 0; i < pts.size(); ++i)
    if (rng() & 1) flip_frame(f, i);
  return f;
}

size_t count_outward(const std::vector<Vec3f>& normals, const std::vector<Vec3f>& truth) {
  size_t agree = 0;
  for (size_t i = 0; i < normals.size(); ++i) agree += normals[i].dot(truth[i]) > 0.f;
  return agree;
}

void expect_right_handed(const LocalFrames& f) {
  for (size_t i = 0; i < f.normals.size(); ++i) {
    ASSERT_LT((f.tangent1[i].cross(f.tangent2[i]) - f.normals[i]).norm(), 1e-5f) << i;
  }
}

TEST(OrientNormalsMst, FibonacciSphereEndsOutward) {
  const PointCloud c = fibonacci_sphere(3000, 2.0);
  const KnnIndex index(c.positions);
  const NeighborGraph graph = knn_graph(index, c.positions, 20);
  LocalFrames f = scrambled_frames(c.positions, index, graph, 1);
  ASSERT_LT(count_outward(f.normals, c.normals), 0.6 * c.size());  // really scrambled
  const OrientNormalsResult r = orient_normals_mst(c.positions, graph, f);
  EXPECT_EQ(r.components, 1u);
  EXPECT_EQ(count_outward(f.normals, c.normals), c.size());
  expect_right_handed(f);
}

TEST(OrientNormalsMst, CountsExactlyTheFlippedFrames) {
  // Start outward, flip a known set: orientation must flip exactly those back.
  const PointCloud c = fibonacci_sphere(2000, 1.0);
  const KnnIndex index(c.positions);
  const NeighborGraph graph = knn_graph(index, c.positions, 20);
  LocalFrames f = estimate_normals(c.positions, index, graph);
  for (size_t i = 0; i < c.size(); ++i)
    if (f.normals[i].dot(c.normals[i]) < 0.f) flip_frame(f, i);
  size_t flipped = 0;
  for (size_t i = 0; i < c.size(); i += 7) {
    flip_frame(f, i);
    ++flipped;
  }
  const OrientNormalsResult r = orient_normals_mst(c.positions, graph, f);
  EXPECT_EQ(r.flipped, flipped);
  EXPECT_EQ(count_outward(f.normals, c.normals), c.size());
}

TEST(OrientNormalsMst, TwoSeparateSpheresAreTwoComponentsBothOutward) {
  // Different radii and heights so the seeds (max Y) differ in kind: one sphere's top
  // is above the other's.
  PointCloud a = fibonacci_sphere(1500, 1.0);
  const PointCloud b = fibonacci_sphere(1500, 1.5);
  const Vec3f ca(-3.f, 0.f, 0.f), cb(3.f, 0.7f, 0.f);
  for (Vec3f& p : a.positions) p += ca;
  std::vector<Vec3f> pts = a.positions;
  std::vector<Vec3f> truth = a.normals;
  for (size_t i = 0; i < b.size(); ++i) {
    pts.push_back(b.positions[i] + cb);
    truth.push_back(b.normals[i]);
  }
  const KnnIndex index(pts);
  const NeighborGraph graph = knn_graph(index, pts, 20);
  LocalFrames f = scrambled_frames(pts, index, graph, 2);
  const OrientNormalsResult r = orient_normals_mst(pts, graph, f);
  EXPECT_EQ(r.components, 2u);
  EXPECT_EQ(count_outward(f.normals, truth), pts.size());
}

TEST(OrientNormalsMst, EllipsoidEndsOutward) {
  // Semi-axes 2, 0.5, 1: curvature varies from 0.125 (at the poles on y) to 8
  // (at the tips on x), and the thin
  // rim around the x axis is where propagation across the two sides could go wrong.
  PointCloud c = fibonacci_sphere(3000, 1.0);
  std::vector<Vec3f> truth(c.size());
  for (size_t i = 0; i < c.size(); ++i) {
    const Vec3f p = c.positions[i];
    c.positions[i] = Vec3f(2.f * p.x(), 0.5f * p.y(), p.z());
    // Normal of x^2/4 + 4 y^2 + z^2 = 1 at the image point: gradient (x/2, 8y, 2z).
    const Vec3f q = c.positions[i];
    truth[i] = Vec3f(q.x() / 4.f, 4.f * q.y(), q.z()).normalized();
  }
  const KnnIndex index(c.positions);
  const NeighborGraph graph = knn_graph(index, c.positions, 20);
  LocalFrames f = scrambled_frames(c.positions, index, graph, 3);
  const OrientNormalsResult r = orient_normals_mst(c.positions, graph, f);
  EXPECT_EQ(r.components, 1u);
  EXPECT_EQ(count_outward(f.normals, truth), c.size());
}

TEST(OrientNormalsMst, BunnyAgreesWithTrueNormals) {
  auto mesh = read_ply_mesh(testing::data_path("bunny.ply"));
  ASSERT_TRUE(mesh.ok()) << mesh.status().message();
  // 20k points on a ~10-unit bunny: spacing ~0.07, enough to resolve the ears.
  const PointCloud c = sample_mesh_uniform(*mesh, 20000, 4, /*with_normals=*/true);
  ASSERT_EQ(c.normals.size(), c.size());
  const KnnIndex index(c.positions);
  const NeighborGraph graph = knn_graph(index, c.positions, 20);
  LocalFrames f = scrambled_frames(c.positions, index, graph, 5);
  const OrientNormalsResult r = orient_normals_mst(c.positions, graph, f);
  EXPECT_EQ(r.components, 1u);
  const size_t agree = count_outward(f.normals, c.normals);
  EXPECT_GT(agree, 0.99 * c.size()) << agree << " of " << c.size();
}

TEST(OrientNormalsTowardCameras, FlipsTowardTheSeeingCamera) {
  // Six cameras on the axes at distance 10; each point seen by the camera it faces
  // most, every tenth point of unknown source.
  const PointCloud sphere = fibonacci_sphere(1200, 1.0);
  PointCloud c;
  c.positions = sphere.positions;
  c.camera_centres = {{10, 0, 0}, {-10, 0, 0}, {0, 10, 0}, {0, -10, 0}, {0, 0, 10}, {0, 0, -10}};
  c.camera.resize(c.size());
  size_t known = 0;
  for (size_t i = 0; i < c.size(); ++i) {
    if (i % 10 == 0) {
      c.camera[i] = kUnknownSource;
      continue;
    }
    int best = 0;
    for (int k = 1; k < 6; ++k) {
      if (c.camera_centres[k].dot(c.positions[i]) > c.camera_centres[best].dot(c.positions[i])) best = k;
    }
    c.camera[i] = best;
    ++known;
  }
  ASSERT_TRUE(c.is_consistent());
  const KnnIndex index(c.positions);
  const NeighborGraph graph = knn_graph(index, c.positions, 20);
  LocalFrames f = scrambled_frames(c.positions, index, graph, 6);
  const LocalFrames before = f;
  EXPECT_EQ(orient_normals_toward_cameras(c, f), known);
  for (size_t i = 0; i < c.size(); ++i) {
    if (c.camera[i] == kUnknownSource) {
      EXPECT_EQ(f.normals[i], before.normals[i]) << "unknown-source point " << i << " was touched";
    } else {
      EXPECT_GT(f.normals[i].dot(sphere.normals[i]), 0.f) << i;
    }
  }
  expect_right_handed(f);
}

TEST(OrientNormalsTowardCameras, NoCamerasDoesNothing) {
  const PointCloud c = fibonacci_sphere(100, 1.0);  // has no camera ids
  const KnnIndex index(c.positions);
  const NeighborGraph graph = knn_graph(index, c.positions, 10);
  LocalFrames f = scrambled_frames(c.positions, index, graph, 7);
  const LocalFrames before = f;
  EXPECT_EQ(orient_normals_toward_cameras(c, f), 0u);
  EXPECT_EQ(f.normals, before.normals);
}

}  // namespace
}  // namespace bodyscan
