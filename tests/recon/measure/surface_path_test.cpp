#include "recon/measure/surface_path.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "recon/io/ply.hpp"
#include "tests/shapes.hpp"
#include "tests/test_meshes.hpp"

namespace bodyscan {
namespace {

using testing::circle;
using testing::merged;
using testing::prism;

double polyline_length(const std::vector<Eigen::Vector3d>& p) {
  double s = 0;
  for (size_t i = 1; i < p.size(); ++i) s += (p[i] - p[i - 1]).norm();
  return s;
}

TEST(SurfacePath, AroundACylinderItIsTheHelixOfTheUnrolledWall) {
  // A 720-sided prism is developable: unrolled, the path is a straight line.
  const double r = 150;
  const TriangleMesh body = prism(circle(r), {0, 0}, 0, 400);
  const auto& c = circle(r);
  const double side = 2 * r * std::sin(M_PI / 720);
  const Eigen::Vector3d a(c[0].x(), 50, c[0].y()), b(c[180].x(), 350, c[180].y());
  auto p = mesh_surface_path(body, a, b);
  ASSERT_TRUE(p.ok()) << p.status().message();
  const double expected = std::hypot(180 * side, 300.0);
  EXPECT_NEAR(p->path_mm, expected, 1e-3);
  EXPECT_NEAR(polyline_length(p->path), p->path_mm, 1e-6);
  // On smooth skin the tape's chords lose almost nothing (radius 150: 0.01 mm).
  EXPECT_NEAR(p->value_mm, p->path_mm, 0.05);
  EXPECT_LE(p->value_mm, p->path_mm + 1e-9);
  EXPECT_NEAR((p->path.front() - a).norm(), 0, 1e-3);
  EXPECT_NEAR((p->path.back() - b).norm(), 0, 1e-3);
  EXPECT_NEAR(p->straight_mm, (b - a).norm(), 1e-3);
  EXPECT_EQ(p->min_confidence, 1.f);
  // It stays on the wall (between the inscribed and the circumscribed circle).
  for (const Eigen::Vector3d& q : p->path) {
    EXPECT_GE(std::hypot(q.x(), q.z()), r * std::cos(M_PI / 720) - 1e-3);
    EXPECT_LE(std::hypot(q.x(), q.z()), r + 1e-3);
  }
}

TEST(SurfacePath, OnACoarsePrismTheStripIsPulledStraight) {
  // Twelve faces: the triangle strip Dijkstra finds zig-zags, the answer does not.
  const double r = 100;
  const auto c = circle(r, {0, 0}, 12);
  const TriangleMesh body = prism(c, {0, 0}, 0, 400, 3);
  const double side = 2 * r * std::sin(M_PI / 12);
  const Eigen::Vector3d a(c[0].x(), 20, c[0].y()), b(c[5].x(), 380, c[5].y());
  auto p = mesh_surface_path(body, a, b);
  ASSERT_TRUE(p.ok()) << p.status().message();
  EXPECT_NEAR(p->path_mm, std::hypot(5 * side, 360.0), 1e-3);
  EXPECT_NEAR(polyline_length(p->path), p->path_mm, 1e-6);
}

// A cube of side 10 * n centred on (0, 50, 0) (y from 0 to 100 for n = 10), each face
// an n x n grid of squares cut into two triangles, wound outward.
TriangleMesh grid_cube(int n) {
  TriangleMesh m;
  std::map<std::array<int, 3>, uint32_t> index;
  auto vertex = [&](std::array<int, 3> g) {
    auto [it, fresh] = index.emplace(g, static_cast<uint32_t>(m.vertices.size()));
    if (fresh) m.vertices.emplace_back(g[0] * 100.f / n - 50, g[1] * 100.f / n, g[2] * 100.f / n - 50);
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side)
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          auto at = [&](int a, int b) {
            std::array<int, 3> g{};
            g[axis] = side * n, g[(axis + 1) % 3] = a, g[(axis + 2) % 3] = b;
            return vertex(g);
          };
          const uint32_t p00 = at(i, j), p10 = at(i + 1, j), p01 = at(i, j + 1), p11 = at(i + 1, j + 1);
          if (side == 1) {
            m.triangles.push_back({p00, p10, p11});
            m.triangles.push_back({p00, p11, p01});
          } else {
            m.triangles.push_back({p00, p11, p10});
            m.triangles.push_back({p00, p01, p11});
          }
        }
  return m;
}

TEST(SurfacePath, OverACubesEdgesItTakesTheShortestUnfolding) {
  const TriangleMesh cube = grid_cube(10);
  ASSERT_TRUE(analyze_topology(cube).closed());
  ASSERT_GT(signed_volume(cube), 0);
  // From the top's centre down a side face: unfolded about the top edge.
  auto p = mesh_surface_path(cube, {0, 100, 0}, {50, 30, 20});
  ASSERT_TRUE(p.ok()) << p.status().message();
  EXPECT_NEAR(p->path_mm, std::hypot(50.0 + 70.0, 20.0), 1e-3);
  // Across the top between opposite faces (round the sides would be 190).
  auto q = mesh_surface_path(cube, {50, 70, -20}, {-50, 80, 30});
  ASSERT_TRUE(q.ok()) << q.status().message();
  EXPECT_NEAR(q->path_mm, std::hypot(30.0 + 100.0 + 20.0, 50.0), 1e-3);
  EXPECT_NEAR(polyline_length(q->path), q->path_mm, 1e-6);
  // Past a corner: from one side face to the top's far corner region, the path may
  // not run through the corner vertex (270 degrees round it: never the shortest way).
  auto c = mesh_surface_path(cube, {50, 60, 40}, {40, 100, 20});
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_NEAR(c->path_mm, std::hypot(40.0 + 10.0, 20.0), 1e-3);
  for (const Eigen::Vector3d& x : c->path) EXPECT_GT((x - Eigen::Vector3d(50, 100, 50)).norm(), 1.0);
}

TEST(SurfacePath, OnASphereItFollowsTheGreatCircle) {
  const double r = 100;
  const TriangleMesh sphere = testing::icosphere(5, r);
  for (double deg : {10.0, 45.0, 90.0, 135.0, 170.0}) {
    const double t = deg * M_PI / 180;
    const Eigen::Vector3d a(0, r, 0),
        b(r * std::sin(t) * std::cos(0.3), r * std::cos(t), r * std::sin(t) * std::sin(0.3));
    auto p = mesh_surface_path(sphere, a, b);
    ASSERT_TRUE(p.ok()) << p.status().message();
    // The polyhedron is inscribed: its geodesics run a little short of the sphere's.
    EXPECT_NEAR(p->path_mm / (r * t), 1.0, 2e-3) << deg;
    EXPECT_LE(p->path_mm, r * t * (1 + 1e-4)) << deg;
    EXPECT_NEAR(polyline_length(p->path), p->path_mm, 1e-6);
    for (const Eigen::Vector3d& x : p->path) EXPECT_NEAR(x.norm(), r, 0.1);
  }
}

TEST(SurfacePath, FlagsInventedSurfaceAndRefusesDisconnectedParts) {
  TriangleMesh body = prism(circle(100, {0, 0}, 90), {0, 0}, 0, 400);
  body.confidence.assign(body.vertices.size(), 1.f);
  for (size_t i = 0; i < body.vertices.size(); ++i)
    if (std::abs(body.vertices[i].y() - 200) < 1 && body.vertices[i].x() > 0) body.confidence[i] = 0;
  auto up = mesh_surface_path(body, {100, 50, 0}, {100, 350, 0});
  ASSERT_TRUE(up.ok()) << up.status().message();
  EXPECT_NEAR(up->path_mm, 300, 1e-3);
  EXPECT_LT(up->min_confidence, 0.5f);
  auto other_side = mesh_surface_path(body, {-100, 50, 0}, {-100, 350, 0});
  ASSERT_TRUE(other_side.ok());
  EXPECT_EQ(other_side->min_confidence, 1.f);

  const TriangleMesh two = merged(body, prism(circle(50, {400, 0}, 60), {400, 0}, 0, 400));
  auto apart = mesh_surface_path(two, {100, 50, 0}, {450, 50, 0});
  ASSERT_FALSE(apart.ok());
  EXPECT_NE(apart.status().message().find("do not connect"), std::string::npos);
  EXPECT_FALSE(mesh_surface_path(TriangleMesh{}, {0, 0, 0}, {1, 1, 1}).ok());
}

// A flat sheet 400 x 60 mm rippled across its length like a scan's noise (0.4 mm
// amplitude, 3 mm wavelength), gridded at 0.5 mm.
TriangleMesh rippled_sheet() {
  TriangleMesh m;
  const int nx = 800, nz = 120;
  for (int i = 0; i <= nx; ++i)
    for (int k = 0; k <= nz; ++k)
      m.vertices.emplace_back(0.5f * i, 0.4f * static_cast<float>(std::sin(2 * M_PI * 0.5 * i / 3.0)), 0.5f * k - 30);
  auto at = [&](int i, int k) { return static_cast<uint32_t>(i * (nz + 1) + k); };
  for (int i = 0; i < nx; ++i)
    for (int k = 0; k < nz; ++k) {
      m.triangles.push_back({at(i, k), at(i, k + 1), at(i + 1, k + 1)});
      m.triangles.push_back({at(i, k), at(i + 1, k + 1), at(i + 1, k)});
    }
  return m;
}

TEST(SurfacePath, TheTapeBridgesRoughnessThePathFollows) {
  const TriangleMesh sheet = rippled_sheet();
  auto p = mesh_surface_path(sheet, {10, 0, 0}, {390, 0, 0});
  ASSERT_TRUE(p.ok()) << p.status().message();
  // The exact path rides every ripple: about 6.5 % long here.
  EXPECT_GT(p->path_mm, 380 * 1.04);
  // The tape, in 10 mm chords, is within 0.5 % of the flat length.
  EXPECT_NEAR(p->value_mm, 380, 0.005 * 380);
  // Without chords the value is the path.
  SurfacePathOptions exact;
  exact.tape_step_mm = 0;
  auto q = mesh_surface_path(sheet, {10, 0, 0}, {390, 0, 0}, exact);
  ASSERT_TRUE(q.ok());
  EXPECT_DOUBLE_EQ(q->value_mm, q->path_mm);
}

TEST(SurfacePath, WithinOneTriangleItIsTheChord) {
  TriangleMesh t;
  t.vertices = {{0, 0, 0}, {100, 0, 0}, {0, 100, 0}};
  t.triangles = {{0, 1, 2}};
  auto p = mesh_surface_path(t, {10, 10, 5}, {40, 30, -5});
  ASSERT_TRUE(p.ok());
  EXPECT_NEAR(p->path_mm, std::hypot(30.0, 20.0), 1e-5);
  EXPECT_EQ(p->path.size(), 2u);
}

TEST(SurfacePath, OfTwoLocallyShortestPathsTheShorter) {
  // The upper back of a true body holds two locally shortest paths between the right
  // acromion and the back neck point: over the trapezius's ridge and round it. The
  // search from the acromion settled into the longer (253.9 mm), the one from the neck
  // into the shorter: both ways now give the shorter.
  auto back = read_ply_mesh(BODYSCAN_SOURCE_DIR "/tests/data/male_heavy_upper_back.ply");
  ASSERT_TRUE(back.ok()) << back.status().message();
  const Eigen::Vector3d acromion(-220.744975, 1434.23018, -125.491871), neck(0, 1501.57812, -181.647546);
  const SurfacePaths paths(*back);
  auto out = paths.shortest(acromion, neck), in = paths.shortest(neck, acromion);
  ASSERT_TRUE(out.ok() && in.ok());
  EXPECT_NEAR(out->path_mm, 240.32, 0.05);
  EXPECT_NEAR(in->path_mm, out->path_mm, 1e-6);
  // Each runs from its first point to its second.
  EXPECT_LT((out->path.front() - acromion).norm(), 1.0);
  EXPECT_LT((out->path.back() - neck).norm(), 1.0);
  EXPECT_LT((in->path.front() - neck).norm(), 1.0);
}

}  // namespace
}  // namespace bodyscan
