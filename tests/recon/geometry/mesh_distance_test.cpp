#include "recon/geometry/mesh_distance.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "recon/geometry/sample_surface.hpp"
#include "recon/io/ply.hpp"
#include "tests/test_data.hpp"
#include "tests/test_meshes.hpp"

namespace bodyscan {
namespace {

using testing::icosphere;
using testing::unit_cube;

const std::string kBodyPath = BODYSCAN_SOURCE_DIR "/hw/sim/bodies/male_average.ply";

TriangleMesh load_mesh(const std::string& path) {
  StatusOr<TriangleMesh> mesh = read_ply_mesh(path);
  EXPECT_TRUE(mesh.ok()) << mesh.status().message();
  return mesh.ok() ? std::move(mesh).value() : TriangleMesh{};
}

// Reference closest distance to one triangle, derived differently from Ericson's
// regions: the projection onto the plane when it falls inside, else the nearest point
// on the three edges. Double precision.
double triangle_distance(const Vec3d& q, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  auto segment = [&](const Vec3d& p0, const Vec3d& p1) {
    const Vec3d d = p1 - p0;
    const double dd = d.squaredNorm();
    const double s = dd > 0 ? std::clamp((q - p0).dot(d) / dd, 0.0, 1.0) : 0.0;
    return (q - (p0 + s * d)).norm();
  };
  double best = std::min({segment(a, b), segment(b, c), segment(c, a)});
  const Vec3d n = (b - a).cross(c - a);
  if (n.squaredNorm() > 0) {
    const Vec3d unit = n.normalized();
    const Vec3d p = q - (q - a).dot(unit) * unit;
    const bool inside =
        (b - a).cross(p - a).dot(n) >= 0 && (c - b).cross(p - b).dot(n) >= 0 && (a - c).cross(p - c).dot(n) >= 0;
    if (inside) best = std::min(best, (q - p).norm());
  }
  return best;
}

double brute_force_distance(const TriangleMesh& m, const Vec3f& q) {
  double best = std::numeric_limits<double>::infinity();
  for (const Triangle& t : m.triangles) {
    best = std::min(best, triangle_distance(q.cast<double>(), m.vertices[t[0]].cast<double>(),
                                            m.vertices[t[1]].cast<double>(), m.vertices[t[2]].cast<double>()));
  }
  return best;
}

double distance_to_triangle(const TriangleMesh& m, uint32_t t, const Vec3f& q) {
  const Triangle& tri = m.triangles[t];
  return triangle_distance(q.cast<double>(), m.vertices[tri[0]].cast<double>(), m.vertices[tri[1]].cast<double>(),
                           m.vertices[tri[2]].cast<double>());
}

// Generalized winding number (Jacobson et al., SIGGRAPH 2013) from the solid angles of
// van Oosterom & Strackee: 1 inside a closed outward-wound mesh, 0 outside.
double winding_number(const TriangleMesh& m, const Vec3d& q) {
  double total = 0;
  for (const Triangle& t : m.triangles) {
    const Vec3d a = m.vertices[t[0]].cast<double>() - q;
    const Vec3d b = m.vertices[t[1]].cast<double>() - q;
    const Vec3d c = m.vertices[t[2]].cast<double>() - q;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double num = a.dot(b.cross(c));
    const double den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    total += 2.0 * std::atan2(num, den);
  }
  return total / (4.0 * std::numbers::pi);
}

std::vector<Vec3f> random_points_in_box(const TriangleMesh& m, double margin, size_t n, uint64_t seed) {
  Vec3f lo = m.vertices[0], hi = m.vertices[0];
  for (const Vec3f& v : m.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const Vec3f pad = Vec3f::Constant(static_cast<float>(margin * (hi - lo).maxCoeff()));
  lo -= pad;
  hi += pad;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<Vec3f> points(n);
  for (Vec3f& p : points) p = lo + Vec3f(u(rng), u(rng), u(rng)).cwiseProduct(hi - lo);
  return points;
}

// Area-weighted vertex normals, computed here so the test needs nothing else.
std::vector<Vec3f> vertex_normals(const TriangleMesh& m) {
  std::vector<Vec3d> sum(m.vertices.size(), Vec3d::Zero());
  for (const Triangle& t : m.triangles) {
    const Vec3d a = m.vertices[t[0]].cast<double>();
    const Vec3d n = (m.vertices[t[1]].cast<double>() - a).cross(m.vertices[t[2]].cast<double>() - a);
    for (uint32_t v : t) sum[v] += n;
  }
  std::vector<Vec3f> normals;
  for (const Vec3d& s : sum) normals.push_back(s.normalized().cast<float>());
  return normals;
}

TEST(MeshDistance, CubeDistancesInFaceEdgeAndVertexRegions) {
  const MeshDistance cube(unit_cube());
  struct Case {
    Vec3f query;
    Vec3f nearest;
    float signed_distance;
  };
  const float r2 = std::sqrt(2.0f), r3 = std::sqrt(3.0f);
  const Case cases[] = {
      {{0.5f, 0.5f, 2.0f}, {0.5f, 0.5f, 1.0f}, 1.0f},  // face region
      {{0.25f, -3.0f, 0.75f}, {0.25f, 0.0f, 0.75f}, 3.0f},
      {{2.0f, 2.0f, 0.5f}, {1.0f, 1.0f, 0.5f}, r2},  // edge region
      {{-1.0f, 0.3f, -1.0f}, {0.0f, 0.3f, 0.0f}, r2},
      {{2.0f, 2.0f, 2.0f}, {1.0f, 1.0f, 1.0f}, r3},  // vertex region
      {{-1.0f, -1.0f, -1.0f}, {0.0f, 0.0f, 0.0f}, r3},
      {{0.5f, 0.5f, 0.7f}, {0.5f, 0.5f, 1.0f}, -0.3f},  // inside
      {{0.9f, 0.5f, 0.5f}, {1.0f, 0.5f, 0.5f}, -0.1f},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(::testing::Message() << "query " << c.query.transpose());
    const ClosestPoint cp = cube.closest_point(c.query);
    EXPECT_NEAR(cp.distance, std::abs(c.signed_distance), 1e-6);
    EXPECT_NEAR(cp.signed_distance, c.signed_distance, 1e-6);
    EXPECT_NEAR((cp.point - c.nearest).norm(), 0.0f, 1e-6);
    EXPECT_LT(cp.triangle, 12u);
  }
  // The centre is equidistant from all six faces.
  EXPECT_NEAR(cube.closest_point(Vec3f(0.5f, 0.5f, 0.5f)).signed_distance, -0.5f, 1e-6);
}

TEST(MeshDistance, QueriesExactlyOnVertexEdgeAndFace) {
  const TriangleMesh sphere = icosphere(2, 50.0);
  const MeshDistance md(sphere);
  for (uint32_t t = 0; t < sphere.triangles.size(); t += 7) {
    const Vec3f a = sphere.vertices[sphere.triangles[t][0]];
    const Vec3f b = sphere.vertices[sphere.triangles[t][1]];
    const Vec3f c = sphere.vertices[sphere.triangles[t][2]];
    const Vec3f on[] = {a, (0.5f * (a + b)).eval(), ((a + b + c) / 3.0f).eval()};
    for (const Vec3f& q : on) {
      const ClosestPoint cp = md.closest_point(q);
      EXPECT_LT(cp.distance, 1e-5f);
      EXPECT_LT(std::abs(cp.signed_distance), 1e-5f);
      EXPECT_LT((cp.point - q).norm(), 1e-5f);
      // Whichever of the touching triangles it reports must really contain the point.
      EXPECT_LT(distance_to_triangle(sphere, cp.triangle, q), 1e-5);
    }
  }
}

TEST(MeshDistance, MatchesBruteForceOnIcosphere) {
  const TriangleMesh sphere = icosphere(3, 100.0);
  const MeshDistance md(sphere);
  EXPECT_EQ(md.num_triangles(), sphere.triangles.size());
  for (const Vec3f& q : random_points_in_box(sphere, 0.5, 500, 11)) {
    const ClosestPoint cp = md.closest_point(q);
    EXPECT_NEAR(cp.distance, brute_force_distance(sphere, q), 1e-4);
    EXPECT_NEAR((q - cp.point).norm(), cp.distance, 1e-4);
    EXPECT_LT(distance_to_triangle(sphere, cp.triangle, cp.point), 1e-4);
    // A convex mesh: inside exactly when nearer the centre than every face plane.
    const float sign_from_radius = q.norm() < 0.95f * 100.0f ? -1.0f : 1.0f;
    if (std::abs(q.norm() - 100.0f) > 5.0f) {
      EXPECT_EQ(std::copysign(1.0f, cp.signed_distance), sign_from_radius);
    }
  }
}

TEST(MeshDistance, MatchesBruteForceOnBunny) {
  const TriangleMesh bunny = load_mesh(bodyscan::testing::data_path("bunny.ply"));
  ASSERT_FALSE(bunny.empty());
  const MeshDistance md(bunny);
  // Half the queries anywhere around the model, half right at its surface where many
  // boxes overlap and pruning matters most.
  std::vector<Vec3f> queries = random_points_in_box(bunny, 0.3, 1000, 5);
  PointCloud near = sample_mesh_uniform(bunny, 1000, 6, false);
  add_gaussian_noise(near, 0.02, 7);
  queries.insert(queries.end(), near.positions.begin(), near.positions.end());
  for (const Vec3f& q : queries) {
    const ClosestPoint cp = md.closest_point(q);
    ASSERT_NEAR(cp.distance, brute_force_distance(bunny, q), 1e-5) << q.transpose();
    EXPECT_LT(distance_to_triangle(bunny, cp.triangle, cp.point), 1e-5);
  }
}

TEST(MeshDistance, SignMatchesWindingNumberOnBunny) {
  const TriangleMesh bunny = load_mesh(bodyscan::testing::data_path("bunny.ply"));
  ASSERT_FALSE(bunny.empty());
  const MeshDistance md(bunny);
  int inside = 0, checked = 0;
  for (const Vec3f& q : random_points_in_box(bunny, 0.05, 1500, 9)) {
    const ClosestPoint cp = md.closest_point(q);
    if (cp.distance < 1e-3f) continue;  // the sign is rounding noise at the surface
    const bool truly_inside = winding_number(bunny, q.cast<double>()) > 0.5;
    EXPECT_EQ(cp.signed_distance < 0, truly_inside) << q.transpose();
    inside += truly_inside;
    ++checked;
  }
  // Both sides were exercised.
  EXPECT_GT(inside, 100);
  EXPECT_GT(checked - inside, 100);
}

TEST(MeshDistance, MatchesBruteForceOnBody) {
  const TriangleMesh body = load_mesh(kBodyPath);
  ASSERT_EQ(body.triangles.size(), 107024u);
  const MeshDistance md(body);
  PointCloud near = sample_mesh_uniform(body, 150, 21, false);
  add_gaussian_noise(near, 10.0, 22);
  std::vector<Vec3f> queries = near.positions;
  const std::vector<Vec3f> far = random_points_in_box(body, 0.2, 50, 23);
  queries.insert(queries.end(), far.begin(), far.end());
  const std::vector<float> batch = md.distances(queries);
  for (size_t i = 0; i < queries.size(); ++i) {
    EXPECT_NEAR(batch[i], brute_force_distance(body, queries[i]), 1e-3) << queries[i].transpose();
  }
}

TEST(MeshDistance, BatchEqualsSingleQueries) {
  const TriangleMesh sphere = icosphere(4, 300.0);
  const MeshDistance md(sphere);
  const std::vector<Vec3f> queries = random_points_in_box(sphere, 0.1, 20000, 3);
  const std::vector<float> batch = md.distances(queries);
  ASSERT_EQ(batch.size(), queries.size());
  for (size_t i = 0; i < queries.size(); ++i) {
    ASSERT_EQ(batch[i], md.closest_point(queries[i]).distance);
  }
  EXPECT_TRUE(md.distances({}).empty());
  EXPECT_EQ(md.distances({Vec3f(0, 0, 400)}).front(), 100.0f);
}

TEST(MeshDistance, DegenerateTrianglesActAsSegments) {
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {5, 5, 5}};
  m.triangles = {{0, 1, 2},   // collinear: the segment from x = 0 to 2
                 {3, 3, 3}};  // a single point
  const MeshDistance md(m);
  const ClosestPoint mid = md.closest_point(Vec3f(1.5f, 2.0f, 0.0f));
  EXPECT_NEAR(mid.distance, 2.0f, 1e-6);
  EXPECT_NEAR((mid.point - Vec3f(1.5f, 0, 0)).norm(), 0.0f, 1e-6);
  EXPECT_FALSE(std::isnan(mid.signed_distance));
  EXPECT_NEAR(md.closest_point(Vec3f(-3, 4, 0)).distance, 5.0f, 1e-6);
  const ClosestPoint point = md.closest_point(Vec3f(5, 5, 7));
  EXPECT_NEAR(point.distance, 2.0f, 1e-6);
  EXPECT_EQ(point.triangle, 1u);
}

TEST(MeshDistance, EmptyMeshIsInfinitelyFar) {
  const MeshDistance md{TriangleMesh{}};
  const ClosestPoint cp = md.closest_point(Vec3f(1, 2, 3));
  EXPECT_TRUE(std::isinf(cp.distance));
  EXPECT_EQ(cp.triangle, kNoTriangle);
  const std::vector<float> d = md.distances({Vec3f::Zero(), Vec3f::Ones()});
  ASSERT_EQ(d.size(), 2u);
  EXPECT_TRUE(std::isinf(d[0]) && std::isinf(d[1]));
}

TEST(SummarizeDistances, PercentilesInterpolateBetweenOrderStatistics) {
  std::vector<float> d(101);
  for (int i = 0; i <= 100; ++i) d[i] = static_cast<float>((i * 37) % 101);  // 0..100 shuffled
  const DistanceStats s = summarize_distances(d);
  EXPECT_EQ(s.count, 101u);
  EXPECT_DOUBLE_EQ(s.mean, 50.0);
  EXPECT_NEAR(s.rms, std::sqrt(3350.0), 1e-9);  // sum of k^2 = 100·101·201/6
  EXPECT_DOUBLE_EQ(s.p50, 50.0);
  EXPECT_DOUBLE_EQ(s.p95, 95.0);
  EXPECT_DOUBLE_EQ(s.p99, 99.0);
  EXPECT_DOUBLE_EQ(s.max, 100.0);

  const DistanceStats two = summarize_distances({10.0f, 0.0f});
  EXPECT_DOUBLE_EQ(two.p50, 5.0);
  EXPECT_DOUBLE_EQ(two.p95, 9.5);
  EXPECT_DOUBLE_EQ(two.max, 10.0);

  const DistanceStats none = summarize_distances({});
  EXPECT_EQ(none.count, 0u);
  EXPECT_EQ(none.max, 0.0);
}

TEST(CompareMeshes, MeshAgainstItselfIsZero) {
  const TriangleMesh body = load_mesh(kBodyPath);
  ASSERT_FALSE(body.empty());
  const MeshComparison c = compare_meshes(body, body, 100000, 1);
  EXPECT_EQ(c.output_to_truth.count, 100000u);
  EXPECT_EQ(c.truth_to_output.count, 100000u);
  // Only float rounding of the samples (positions up to 1.7 m) separates them.
  EXPECT_LT(c.output_to_truth.max, 1e-3);
  EXPECT_LT(c.truth_to_output.max, 1e-3);
  EXPECT_LT(c.output_to_truth.mean, 1e-4);
}

TEST(CompareMeshes, SphereOffsetByOneMillimetre) {
  // Same lattice at radius 100 and 101: corresponding faces are parallel planes
  // 1·cos(θ) apart, θ < 0.04 rad between a face's normal and its corners.
  const TriangleMesh inner = icosphere(4, 100.0);
  const TriangleMesh outer = icosphere(4, 101.0);
  const MeshComparison c = compare_meshes(outer, inner, 50000, 2);
  for (const DistanceStats& s : {c.output_to_truth, c.truth_to_output}) {
    EXPECT_NEAR(s.mean, 1.0, 2e-3);
    EXPECT_NEAR(s.p50, 1.0, 2e-3);
    EXPECT_NEAR(s.max, 1.0, 2e-3);
    EXPECT_GT(s.p50, 0.99);
  }
}

TEST(CompareMeshes, BodyOffsetAlongNormalsByOneMillimetre) {
  const TriangleMesh body = load_mesh(kBodyPath);
  ASSERT_FALSE(body.empty());
  TriangleMesh grown = body;
  const std::vector<Vec3f> normals = vertex_normals(body);
  for (size_t v = 0; v < grown.vertices.size(); ++v) grown.vertices[v] += normals[v];
  const MeshComparison c = compare_meshes(grown, body, 100000, 3);
  // Flat regions sit exactly 1 mm away; creases and fingertips pull the tails.
  for (const DistanceStats& s : {c.output_to_truth, c.truth_to_output}) {
    EXPECT_NEAR(s.p50, 1.0, 0.01);
    EXPECT_NEAR(s.mean, 1.0, 0.01);
    EXPECT_LT(s.max, 1.05);
  }
}

}  // namespace
}  // namespace bodyscan
