#include "recon/measure/plane_section.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "tests/shapes.hpp"

namespace bodyscan {
namespace {

Plane horizontal(double y) { return {Eigen::Vector3d(0, y, 0), Eigen::Vector3d::UnitY()}; }

// A vertical strip from the origin out along direction (dx, dz): `n` quads wide,
// y from 0 to 10.
void fin(double dx, double dz, int n, uint32_t shared_bottom, uint32_t shared_top, TriangleMesh* into) {
  TriangleMesh& m = *into;
  std::vector<uint32_t> bottom{shared_bottom}, top{shared_top};
  for (int i = 1; i <= n; ++i) {
    bottom.push_back(static_cast<uint32_t>(m.vertices.size()));
    m.vertices.emplace_back(static_cast<float>(i * dx), 0.f, static_cast<float>(i * dz));
    top.push_back(static_cast<uint32_t>(m.vertices.size()));
    m.vertices.emplace_back(static_cast<float>(i * dx), 10.f, static_cast<float>(i * dz));
  }
  for (int i = 0; i < n; ++i) {
    m.triangles.push_back({bottom[i], bottom[i + 1], top[i + 1]});
    m.triangles.push_back({bottom[i], top[i + 1], top[i]});
  }
}

TEST(PlaneSection, AClosedPrismGivesOneClosedLoopAroundIt) {
  const TriangleMesh m = testing::prism(testing::circle(50, {0, 0}, 90), {0, 0}, 0, 100);
  const std::vector<SectionLoop> loops = plane_section(m, horizontal(37.3));
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_TRUE(loops[0].closed);
  // Each side quad is two triangles: the cut crosses its vertical edges and its diagonal.
  const size_t n = loops[0].points.size();
  EXPECT_EQ(n, 180u);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& p = loops[0].points[i];
    EXPECT_NEAR(p.y(), 37.3, 1e-9);
    // Neighbours along the loop are neighbours on the circle (no jumps across).
    EXPECT_LT((p - loops[0].points[(i + 1) % n]).norm(), 2 * 50 * std::sin(M_PI / 90) + 1e-6);
  }
}

TEST(PlaneSection, ASweepsPerPlaneTrianglesCutTheSameLoopsAsTheWholeMesh) {
  // Tilted planes, and level ones through the prism's rims, where corners lie on
  // the plane: every loop, point for point, as cut through every triangle.
  const TriangleMesh m = testing::prism(testing::circle(50, {3, -2}, 90), {0, 0}, 0, 100);
  std::vector<uint32_t> all(m.num_triangles());
  for (uint32_t t = 0; t < all.size(); ++t) all[t] = t;
  const std::vector<Eigen::Vector3d> normals = {Eigen::Vector3d(0.3, 1, 0.2).normalized(), Eigen::Vector3d::UnitY()};
  for (const Eigen::Vector3d& normal : normals) {
    const Eigen::Vector3d origin(1, 0, 0);
    std::vector<double> offsets;
    for (double t = -20; t <= 120; t += 2.5) offsets.push_back(t);
    const std::vector<std::vector<uint32_t>> lists = triangles_by_plane(m, all, origin, normal, offsets);
    ASSERT_EQ(lists.size(), offsets.size());
    size_t cut = 0;
    for (size_t k = 0; k < offsets.size(); ++k) {
      const Plane plane{origin + offsets[k] * normal, normal};
      const std::vector<SectionLoop> want = plane_section(m, plane);
      const std::vector<SectionLoop> got = plane_section(m, plane, &lists[k]);
      EXPECT_LT(lists[k].size(), m.num_triangles() / 4) << offsets[k];
      ASSERT_EQ(got.size(), want.size()) << offsets[k];
      for (size_t i = 0; i < want.size(); ++i) {
        EXPECT_EQ(got[i].closed, want[i].closed);
        EXPECT_EQ(got[i].points, want[i].points) << offsets[k];
      }
      cut += want.empty() ? 0 : 1;
    }
    EXPECT_GT(cut, 30u);
  }
}

TEST(PlaneSection, AnOpenSheetGivesOnePolylineAcrossIt) {
  TriangleMesh m;
  m.vertices.emplace_back(0.f, 0.f, 0.f);
  m.vertices.emplace_back(0.f, 10.f, 0.f);
  fin(1, 0, 20, 0, 1, &m);
  const std::vector<SectionLoop> loops = plane_section(m, horizontal(4));
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_FALSE(loops[0].closed);
  ASSERT_EQ(loops[0].points.size(), 41u);  // 21 vertical edges and 20 diagonals
  // From one border to the other, in order along x.
  const bool rising = loops[0].points.front().x() < loops[0].points.back().x();
  for (size_t i = 1; i < loops[0].points.size(); ++i)
    EXPECT_EQ(loops[0].points[i].x() > loops[0].points[i - 1].x(), rising) << i;
  EXPECT_NEAR(std::min(loops[0].points.front().x(), loops[0].points.back().x()), 0, 1e-9);
  EXPECT_NEAR(std::max(loops[0].points.front().x(), loops[0].points.back().x()), 20, 1e-9);
}

TEST(PlaneSection, AnEdgeThreeSheetsShareIsWalkedThroughOnce) {
  // Three fins meet along the vertical edge at the origin (a non-manifold edge):
  // the cut crosses it in three segments. The walk from one fin's outer border
  // goes through the shared edge into another fin and out; the third fin is a
  // polyline of its own that ends at the shared edge. Every crossing is kept.
  TriangleMesh m;
  m.vertices.emplace_back(0.f, 0.f, 0.f);
  m.vertices.emplace_back(0.f, 10.f, 0.f);
  fin(1, 0, 5, 0, 1, &m);
  fin(-0.5, 0.866, 5, 0, 1, &m);
  fin(-0.5, -0.866, 5, 0, 1, &m);
  const std::vector<SectionLoop> loops = plane_section(m, horizontal(6));
  ASSERT_EQ(loops.size(), 2u);
  size_t points = 0, at_shared_edge = 0;
  for (const SectionLoop& l : loops) {
    EXPECT_FALSE(l.closed);
    points += l.points.size();
    for (const Eigen::Vector3d& p : l.points) {
      EXPECT_NEAR(p.y(), 6, 1e-9);
      if (p.head<1>().norm() < 1e-9 && std::abs(p.z()) < 1e-9) ++at_shared_edge;
    }
  }
  // Each fin: 5 outer vertical edges and 5 diagonals; the shared edge once per polyline.
  EXPECT_EQ(points, 3u * 10 + 2);
  EXPECT_EQ(at_shared_edge, 2u);
}

}  // namespace
}  // namespace bodyscan
