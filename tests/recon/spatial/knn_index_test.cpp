// KnnIndex and knn_graph against brute force on seeded random clouds.
#include "recon/spatial/knn_index.hpp"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

namespace bodyscan {
namespace {

// Uniform in [0, 1) from the top 53 bits (the same on every standard library).
double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

std::vector<Vec3f> random_cloud(size_t n, float extent, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Vec3f> p(n);
  for (Vec3f& v : p) {
    v = Vec3f(static_cast<float>(uniform01(rng)), static_cast<float>(uniform01(rng)),
              static_cast<float>(uniform01(rng))) *
        extent;
  }
  return p;
}

// Squared distance in double: the reference that float results are held to.
double sq_dist(const Vec3f& a, const Vec3f& b) { return (a.cast<double>() - b.cast<double>()).squaredNorm(); }

// All points ordered by distance to q (ties by index).
std::vector<std::pair<double, uint32_t>> brute_sorted(const std::vector<Vec3f>& pts, const Vec3f& q) {
  std::vector<std::pair<double, uint32_t>> all(pts.size());
  for (size_t i = 0; i < pts.size(); ++i) all[i] = {sq_dist(pts[i], q), static_cast<uint32_t>(i)};
  std::sort(all.begin(), all.end());
  return all;
}

// Float squared distances of points of size ~1 agree with double to a few ulps of
// the coordinates' squares; 1e-5 relative plus 1e-9 absolute is far above that and
// far below the spacing of 1000 random points in a unit cube (~0.06, squared 4e-3).
constexpr double kRelTol = 1e-5;
constexpr double kAbsTol = 1e-9;

TEST(KnnIndex, KnnMatchesBruteForce) {
  const std::vector<Vec3f> pts = random_cloud(1000, 1.f, 11);
  const KnnIndex index(pts);
  ASSERT_EQ(index.size(), pts.size());
  // Queries: some cloud points (their own distance 0 must come first) and some
  // free positions, including outside the cloud's box.
  std::vector<Vec3f> queries(pts.begin(), pts.begin() + 20);
  const std::vector<Vec3f> free_q = random_cloud(20, 1.6f, 12);
  for (const Vec3f& q : free_q) queries.push_back(q - Vec3f::Constant(0.3f));
  for (size_t k : {size_t{1}, size_t{7}, size_t{32}}) {
    std::vector<uint32_t> idx(k);
    std::vector<float> d2(k);
    for (size_t qi = 0; qi < queries.size(); ++qi) {
      const Vec3f& q = queries[qi];
      const size_t got = index.knn(q, k, idx.data(), d2.data());
      ASSERT_EQ(got, k);
      const auto ref = brute_sorted(pts, q);
      for (size_t j = 0; j < k; ++j) {
        EXPECT_EQ(idx[j], ref[j].second) << "query " << qi << " k " << k << " rank " << j;
        EXPECT_NEAR(d2[j], ref[j].first, kRelTol * ref[j].first + kAbsTol);
        if (j > 0) {
          EXPECT_LE(d2[j - 1], d2[j]);
        }
      }
      if (qi < 20) {
        EXPECT_EQ(idx[0], qi);  // the query point itself
        EXPECT_EQ(d2[0], 0.f);
      }
    }
  }
}

TEST(KnnIndex, WithinRadiusMatchesBruteForce) {
  const std::vector<Vec3f> pts = random_cloud(1000, 1.f, 21);
  const KnnIndex index(pts);
  const std::vector<Vec3f> queries = random_cloud(30, 1.f, 22);
  for (float radius : {0.05f, 0.15f, 0.3f}) {
    for (const Vec3f& q : queries) {
      const auto got = index.within_radius(q, radius);
      // Nearest first.
      for (size_t j = 1; j < got.size(); ++j) EXPECT_LE(got[j - 1].second, got[j].second);
      const double r2 = static_cast<double>(radius) * radius;
      std::vector<uint32_t> got_ids;
      for (const auto& [i, d2] : got) {
        got_ids.push_back(i);
        EXPECT_NEAR(d2, sq_dist(pts[i], q), kRelTol * r2 + kAbsTol);
        EXPECT_LE(sq_dist(pts[i], q), r2 * (1 + kRelTol));
      }
      std::sort(got_ids.begin(), got_ids.end());
      EXPECT_EQ(std::adjacent_find(got_ids.begin(), got_ids.end()), got_ids.end()) << "duplicate result";
      // Every point clearly inside the ball must be found; points within float
      // rounding of the sphere may go either way.
      size_t clearly_inside = 0;
      for (size_t i = 0; i < pts.size(); ++i) {
        const double d2 = sq_dist(pts[i], q);
        if (d2 < r2 * (1 - kRelTol)) {
          ++clearly_inside;
          EXPECT_TRUE(std::binary_search(got_ids.begin(), got_ids.end(), static_cast<uint32_t>(i)))
              << "missed point " << i << " at distance " << std::sqrt(d2) << " < " << radius;
        }
      }
      EXPECT_GE(got.size(), clearly_inside);
    }
  }
  // A radius reaching nothing gives nothing.
  EXPECT_TRUE(index.within_radius(Vec3f(10.f, 10.f, 10.f), 1.f).empty());
}

TEST(KnnIndex, KnnReturnsAllPointsWhenKExceedsSize) {
  const std::vector<Vec3f> pts = {{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 3.f, 0.f}};
  const KnnIndex index(pts);
  std::vector<uint32_t> idx(10, 99);
  std::vector<float> d2(10, -1.f);
  ASSERT_EQ(index.knn(Vec3f(0.f, 0.1f, 0.f), 10, idx.data(), d2.data()), 3u);
  EXPECT_EQ(idx[0], 0u);
  EXPECT_EQ(idx[1], 1u);
  EXPECT_EQ(idx[2], 2u);
  EXPECT_FLOAT_EQ(d2[0], 0.01f);
  EXPECT_FLOAT_EQ(d2[1], 1.01f);
  EXPECT_FLOAT_EQ(d2[2], 2.9f * 2.9f);
  // Entries past n are not written.
  EXPECT_EQ(idx[3], 99u);
  EXPECT_EQ(index.knn(Vec3f::Zero(), 0, idx.data(), d2.data()), 0u);
}

TEST(KnnIndex, EmptyIndex) {
  const std::vector<Vec3f> pts;
  const KnnIndex index(pts);
  EXPECT_EQ(index.size(), 0u);
  uint32_t idx[4];
  float d2[4];
  EXPECT_EQ(index.knn(Vec3f::Zero(), 4, idx, d2), 0u);
  const NeighborGraph g = knn_graph(index, pts, 5);
  EXPECT_EQ(g.k, 0u);
  EXPECT_TRUE(g.indices.empty());
}

// Row i of the graph is the brute-force k nearest of point i other than i itself,
// nearest first, with plain (not squared) distances.
void expect_graph_matches_brute_force(const std::vector<Vec3f>& pts, const NeighborGraph& g) {
  ASSERT_EQ(g.indices.size(), pts.size() * g.k);
  ASSERT_EQ(g.distances.size(), pts.size() * g.k);
  for (size_t i = 0; i < pts.size(); ++i) {
    auto ref = brute_sorted(pts, pts[i]);
    ref.erase(std::find_if(ref.begin(), ref.end(), [&](const auto& e) { return e.second == i; }));
    const uint32_t* row = g.row(i);
    const float* dist = g.row_distances(i);
    for (size_t j = 0; j < g.k; ++j) {
      ASSERT_NE(row[j], i) << "point " << i << " lists itself";
      EXPECT_EQ(row[j], ref[j].second) << "point " << i << " rank " << j;
      EXPECT_NEAR(dist[j], std::sqrt(ref[j].first), 1e-5 * std::sqrt(ref[j].first) + 1e-7);
      if (j > 0) {
        EXPECT_LE(dist[j - 1], dist[j]);
      }
    }
  }
}

TEST(KnnGraph, ExcludesSelfSortedAndMatchesBruteForce) {
  const std::vector<Vec3f> pts = random_cloud(600, 1.f, 31);
  const KnnIndex index(pts);
  const NeighborGraph g = knn_graph(index, pts, 12);
  ASSERT_EQ(g.k, 12u);
  expect_graph_matches_brute_force(pts, g);
}

TEST(KnnGraph, DoesNotDependOnThreadCount) {
  const std::vector<Vec3f> pts = random_cloud(5000, 1.f, 32);
  const KnnIndex index(pts);
  const NeighborGraph parallel = knn_graph(index, pts, 10);
  NeighborGraph serial;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    serial = knn_graph(index, pts, 10);
  }
  EXPECT_EQ(parallel.indices, serial.indices);
  EXPECT_EQ(parallel.distances, serial.distances);
}

TEST(KnnGraph, ExactDuplicates) {
  // Every point three times: its two copies are its nearest others at distance 0, and
  // it never lists itself even though its copies tie with it.
  const std::vector<Vec3f> base = random_cloud(200, 1.f, 41);
  std::vector<Vec3f> pts;
  for (int copy = 0; copy < 3; ++copy) pts.insert(pts.end(), base.begin(), base.end());
  const KnnIndex index(pts);
  const NeighborGraph g = knn_graph(index, pts, 4);
  ASSERT_EQ(g.k, 4u);
  const size_t n = base.size();
  for (size_t i = 0; i < pts.size(); ++i) {
    const uint32_t* row = g.row(i);
    const float* dist = g.row_distances(i);
    std::vector<uint32_t> first_two = {row[0], row[1]};
    std::sort(first_two.begin(), first_two.end());
    std::vector<uint32_t> copies;
    for (size_t c = 0; c < 3; ++c)
      if (c * n + i % n != i) copies.push_back(static_cast<uint32_t>(c * n + i % n));
    EXPECT_EQ(first_two, copies) << "point " << i;
    EXPECT_EQ(dist[0], 0.f);
    EXPECT_EQ(dist[1], 0.f);
    EXPECT_GT(dist[2], 0.f);
    for (size_t j = 0; j < g.k; ++j) EXPECT_NE(row[j], i);
  }
}

TEST(KnnGraph, ManyDuplicatesOfOnePoint) {
  // 10 identical points and k = 4: more zero-distance ties than k + 1, so the search
  // may return the other copies without the point itself.
  std::vector<Vec3f> pts(10, Vec3f(0.5f, 0.5f, 0.5f));
  pts.push_back(Vec3f(2.f, 0.f, 0.f));
  const KnnIndex index(pts);
  const NeighborGraph g = knn_graph(index, pts, 4);
  ASSERT_EQ(g.k, 4u);
  for (size_t i = 0; i < 10; ++i) {
    for (size_t j = 0; j < 4; ++j) {
      EXPECT_NE(g.row(i)[j], i);
      EXPECT_LT(g.row(i)[j], 10u);
      EXPECT_EQ(g.row_distances(i)[j], 0.f);
    }
  }
  // The outlier's neighbours are copies at the same distance.
  for (size_t j = 0; j < 4; ++j) {
    EXPECT_LT(g.row(10)[j], 10u);
    EXPECT_NEAR(g.row_distances(10)[j], std::sqrt(1.5f * 1.5f + 0.5f), 1e-6f);
  }
}

TEST(KnnGraph, TinyCloudsReduceK) {
  {
    const std::vector<Vec3f> pts = {{0.f, 0.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 2.f, 0.f}};
    const KnnIndex index(pts);
    const NeighborGraph g = knn_graph(index, pts, 10);
    ASSERT_EQ(g.k, 2u);  // k >= n: each point lists the n - 1 others
    expect_graph_matches_brute_force(pts, g);
    EXPECT_EQ(g.row(0)[0], 1u);
    EXPECT_EQ(g.row(0)[1], 2u);
    EXPECT_FLOAT_EQ(g.row_distances(2)[0], 2.f);
    EXPECT_FLOAT_EQ(g.row_distances(2)[1], std::sqrt(5.f));
  }
  {
    const std::vector<Vec3f> pts = {{1.f, 2.f, 3.f}};
    const KnnIndex index(pts);
    const NeighborGraph g = knn_graph(index, pts, 3);
    EXPECT_EQ(g.k, 0u);
    EXPECT_TRUE(g.indices.empty());
    EXPECT_TRUE(g.distances.empty());
  }
  {
    // k == n - 1 exactly.
    const std::vector<Vec3f> pts = random_cloud(8, 1.f, 51);
    const KnnIndex index(pts);
    const NeighborGraph g = knn_graph(index, pts, 7);
    ASSERT_EQ(g.k, 7u);
    expect_graph_matches_brute_force(pts, g);
  }
}

}  // namespace
}  // namespace bodyscan
