#include "recon/measure/girth.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "recon/geometry/sample_surface.hpp"
#include "tests/shapes.hpp"

namespace bodyscan {
namespace {

using testing::circle;
using testing::merged;
using testing::prism;

Plane horizontal(double y) { return {Eigen::Vector3d(0, y, 0), Eigen::Vector3d::UnitY()}; }

TEST(ConvexHull, KeepsTheCornersCounterClockwise) {
  const std::vector<Eigen::Vector2d> pts = {{0, 0}, {2, 0}, {1, 1}, {2, 2}, {0, 2}, {1, 0}, {1, 1.9}};
  const auto h = convex_hull(pts);
  ASSERT_EQ(h.size(), 4u);  // the collinear (1, 0) and the inner points go
  double area = 0;
  for (size_t i = 0; i < h.size(); ++i)
    area += h[i].x() * h[(i + 1) % h.size()].y() - h[(i + 1) % h.size()].x() * h[i].y();
  EXPECT_NEAR(area / 2, 4.0, 1e-12);  // positive: counter-clockwise
  EXPECT_NEAR(closed_length(h), 8.0, 1e-12);
  EXPECT_EQ(convex_hull({{1, 1}, {1, 1}}).size(), 1u);
}

TEST(MeshGirth, ACylinderMeasuresItsCircumference) {
  const TriangleMesh body = prism(circle(150), {0, 0}, 0, 400);
  auto g = mesh_girth(body, horizontal(213.7));
  ASSERT_TRUE(g.ok()) << g.status().message();
  const double polygon = 2 * 720 * 150 * std::sin(M_PI / 720);  // the mesh's own circumference
  EXPECT_NEAR(g->value_mm, polygon, 1e-6);
  EXPECT_NEAR(g->loop_length_mm, polygon, 1e-6);
  EXPECT_EQ(g->loops_cut, 1u);
  EXPECT_EQ(g->min_confidence, 1.f);
  for (const Eigen::Vector3d& p : g->loop) EXPECT_NEAR(p.y(), 213.7, 1e-9);
  // A tilted plane cuts an ellipse: semi-axes 150 and 150 / cos(30°).
  const Plane tilted{{0, 200, 0}, Eigen::Vector3d(std::sin(M_PI / 6), std::cos(M_PI / 6), 0)};
  auto e = mesh_girth(body, tilted);
  ASSERT_TRUE(e.ok());
  const double a = 150 / std::cos(M_PI / 6), b = 150, h = std::pow(a - b, 2) / std::pow(a + b, 2);
  const double ramanujan = M_PI * (a + b) * (1 + 3 * h / (10 + std::sqrt(4 - 3 * h)));
  EXPECT_NEAR(e->value_mm, ramanujan, 0.05);
}

TEST(MeshGirth, TheTapeBridgesHollows) {
  // A cross section with a deep notch (a "C"): the tape spans the notch, the loop
  // follows it.
  std::vector<Eigen::Vector2d> c;
  for (int i = 0; i < 360; ++i) {
    const double a = 2 * M_PI * i / 360;
    const double r = std::abs(std::remainder(a, 2 * M_PI)) < 0.3 ? 60 : 100;  // a notch facing +x
    c.push_back(r * Eigen::Vector2d(std::cos(a), -std::sin(a)));
  }
  const TriangleMesh body = prism(c, {0, 0}, 0, 100, 2);
  auto g = mesh_girth(body, horizontal(50));
  ASSERT_TRUE(g.ok());
  // In 1-degree steps the notch holds the samples within 17 degrees of +x; the tape
  // leaves the circle at 18 degrees each side. The loop adds the notch's inner arc
  // (34 one-degree chords of radius 60) and two walls, where the tape takes one chord.
  const double deg = M_PI / 180;
  const Eigen::Vector2d inner(60 * std::cos(17 * deg), 60 * std::sin(17 * deg)),
      outer(100 * std::cos(18 * deg), 100 * std::sin(18 * deg));
  const double notch = 34 * 2 * 60 * std::sin(deg / 2) + 2 * (outer - inner).norm();
  EXPECT_NEAR(g->loop_length_mm - g->value_mm, notch - 200 * std::sin(18 * deg), 1e-3);
  EXPECT_NEAR(g->value_mm, 324 * 2 * 100 * std::sin(deg / 2) + 200 * std::sin(18 * deg), 1e-3);
}

TEST(MeshGirth, TheLoopMeantIsTheOneNearestThePoint) {
  // A torso and an arm beside it, cut by one plane at the waist.
  const TriangleMesh torso = prism(circle(150), {0, 0}, 0, 600);
  const TriangleMesh arm = prism(circle(40, {230, 0}, 360), {230, 0}, 100, 600);
  const TriangleMesh body = merged(torso, arm);
  auto waist = mesh_girth(body, horizontal(300));
  ASSERT_TRUE(waist.ok());
  EXPECT_EQ(waist->loops_cut, 2u);
  EXPECT_NEAR(waist->value_mm, 2 * M_PI * 150, 0.1);  // without a point: the longest tape
  auto upper_arm = mesh_girth(body, horizontal(300), Eigen::Vector3d(235, 300, 10));
  ASSERT_TRUE(upper_arm.ok());
  EXPECT_NEAR(upper_arm->value_mm, 2 * M_PI * 40, 0.1);
  // Never both together.
  EXPECT_LT(upper_arm->value_mm, 300);
}

TEST(MeshGirth, ACavityInsideTheBodyIsNeverTheLoop) {
  // A bubble the reconstruction left inside the torso: its wall is a loop of the
  // cut, inside the skin's. Even a point inside the bubble means the torso.
  const TriangleMesh torso = prism(circle(150), {0, 0}, 0, 600);
  const TriangleMesh bubble = prism(circle(40, {60, 0}, 360), {60, 0}, 250, 350);
  const TriangleMesh body = merged(torso, bubble);
  const Eigen::Vector3d in_bubble(60, 300, 0);
  auto g = mesh_girth(body, horizontal(300), in_bubble);
  ASSERT_TRUE(g.ok());
  EXPECT_EQ(g->loops_cut, 2u);
  EXPECT_NEAR(g->value_mm, 2 * M_PI * 150, 0.1);
  // A part of its own beside the torso still counts.
  const TriangleMesh arm = prism(circle(40, {230, 0}, 360), {230, 0}, 100, 600);
  auto a = mesh_girth(merged(body, arm), horizontal(300), Eigen::Vector3d(230, 300, 0));
  ASSERT_TRUE(a.ok());
  EXPECT_NEAR(a->value_mm, 2 * M_PI * 40, 0.1);
  std::vector<SectionLoop> loops = plane_section(merged(body, arm), horizontal(300));
  ASSERT_EQ(loops.size(), 3u);
  drop_nested_loops(&loops, horizontal(300));
  EXPECT_EQ(loops.size(), 2u);
}

TEST(MeshGirth, LoopsThatCrossAreOnePartAndTheTapeGoesRoundBoth) {
  // A reconstructed surface can pass through itself: a hole's fill can run through
  // an ankle, whose cut then becomes two overlapping loops (heel and front), and a
  // tape round one alone falls tens of mm short. Two crossing ovals here: the tape goes
  // round both, whichever is nearer the point; a part beside them stays apart.
  const TriangleMesh heel = prism(circle(40, {0, 0}, 360), {0, 0}, 0, 200);
  const TriangleMesh front = prism(circle(40, {50, 0}, 360), {50, 0}, 0, 200);
  const TriangleMesh other = prism(circle(40, {200, 0}, 360), {200, 0}, 0, 200);
  const TriangleMesh body = merged(merged(heel, front), other);
  const double both = 2 * M_PI * 40 + 2 * 50;  // the hull of two circles 50 apart
  for (const Eigen::Vector3d& near : {Eigen::Vector3d(-10, 110, 0), Eigen::Vector3d(60, 110, 0)}) {
    auto g = mesh_girth(body, horizontal(110), near);
    ASSERT_TRUE(g.ok());
    EXPECT_EQ(g->loops_cut, 3u);
    EXPECT_NEAR(g->value_mm, both, 0.1) << near.transpose();
  }
  auto apart = mesh_girth(body, horizontal(110), Eigen::Vector3d(200, 110, 0));
  ASSERT_TRUE(apart.ok());
  EXPECT_NEAR(apart->value_mm, 2 * M_PI * 40, 0.1);
}

TEST(MeshGirth, ClearErrors) {
  const TriangleMesh body = prism(circle(150), {0, 0}, 0, 400);
  auto miss = mesh_girth(body, horizontal(500));
  EXPECT_EQ(miss.status().code(), StatusCode::kNotFound);
  EXPECT_NE(miss.status().message().find("does not cut"), std::string::npos);
  EXPECT_FALSE(mesh_girth(body, {{0, 0, 0}, Eigen::Vector3d::Zero()}).ok());
  // An open tube cut lengthwise: only open polylines.
  TriangleMesh tube = body;
  tube.triangles.resize(tube.triangles.size() - 2 * 720);  // the caps go
  auto open = mesh_girth(tube, {{0, 200, 0}, Eigen::Vector3d::UnitX()});
  EXPECT_EQ(open.status().code(), StatusCode::kNotFound);
  EXPECT_NE(open.status().message().find("open border"), std::string::npos) << open.status().message();
}

TEST(MeshGirth, LoopsThroughFilledHolesAreFlagged) {
  TriangleMesh body = prism(circle(150), {0, 0}, 0, 400);
  body.confidence.assign(body.vertices.size(), 1.f);
  for (size_t i = 0; i < body.vertices.size(); ++i)
    if (body.vertices[i].x() > 140) body.confidence[i] = 0.f;  // a filled hole on the +x side
  auto g = mesh_girth(body, horizontal(210));
  ASSERT_TRUE(g.ok());
  EXPECT_LT(g->min_confidence, 0.5f);
  // A hole filled high up leaves a loop lower down all measured.
  for (size_t i = 0; i < body.vertices.size(); ++i) body.confidence[i] = body.vertices[i].y() > 300 ? 0.f : 1.f;
  auto low = mesh_girth(body, horizontal(110));
  ASSERT_TRUE(low.ok());
  EXPECT_EQ(low->min_confidence, 1.f);
  auto high = mesh_girth(body, horizontal(330));
  ASSERT_TRUE(high.ok());
  EXPECT_NEAR(high->min_confidence, 0.4f, 1e-5);  // 30 of the 50 mm from a measured ring to a filled one
}

TEST(MeshArc, FollowsTheTapeTheShorterWayRound) {
  const TriangleMesh body = prism(circle(150), {0, 0}, 0, 400);
  const double perimeter = 2 * 720 * 150 * std::sin(M_PI / 720);
  // From the front (+z) to the right side (+x), a quarter of the way round.
  auto a = mesh_arc(body, horizontal(210), Eigen::Vector3d(0, 210, 170), Eigen::Vector3d(160, 215, 0));
  ASSERT_TRUE(a.ok()) << a.status().message();
  EXPECT_NEAR(a->value_mm, perimeter / 4, 1e-3);
  EXPECT_NEAR(a->other_way_mm, 3 * perimeter / 4, 1e-3);
  EXPECT_NEAR(a->girth.value_mm, perimeter, 1e-3);
  ASSERT_GE(a->path.size(), 3u);
  EXPECT_NEAR((a->path.front() - Eigen::Vector3d(0, 210, 150)).norm(), 0, 1e-3);  // from the first point
  EXPECT_NEAR((a->path.back() - Eigen::Vector3d(150, 210, 0)).norm(), 0, 1e-3);   // to the second
  EXPECT_NEAR(closed_length(a->path) - (a->path.back() - a->path.front()).norm(), a->value_mm, 1e-3);
  // Across the notch of a "C" the arc takes the tape's chord, not the notch.
  std::vector<Eigen::Vector2d> c;
  for (int i = 0; i < 360; ++i) {
    const double ang = 2 * M_PI * i / 360;
    c.push_back((std::abs(std::remainder(ang, 2 * M_PI)) < 0.3 ? 60 : 100) *
                Eigen::Vector2d(std::cos(ang), -std::sin(ang)));
  }
  const double deg = M_PI / 180;
  auto across = mesh_arc(prism(c, {0, 0}, 0, 100, 2), horizontal(50),
                         Eigen::Vector3d(100 * std::cos(18 * deg), 50, 100 * std::sin(18 * deg)),
                         Eigen::Vector3d(100 * std::cos(18 * deg), 50, -100 * std::sin(18 * deg)));
  ASSERT_TRUE(across.ok());
  EXPECT_NEAR(across->value_mm, 200 * std::sin(18 * deg), 1e-3);
}

TEST(CloudGirth, PointsNearThePlaneMeasureLikeTheMesh) {
  const TriangleMesh torso = prism(circle(150), {0, 0}, 0, 600);
  const TriangleMesh arm = prism(circle(40, {250, 0}, 360), {250, 0}, 100, 600);
  const PointCloud cloud = sample_mesh_uniform(merged(torso, arm), 400000, 3, false);
  auto waist = cloud_girth(cloud, horizontal(300), std::nullopt);
  ASSERT_TRUE(waist.ok()) << waist.status().message();
  EXPECT_EQ(waist->loops_cut, 2u);
  EXPECT_NEAR(waist->value_mm, 2 * M_PI * 150, 2.0);
  auto upper_arm = cloud_girth(cloud, horizontal(300), Eigen::Vector3d(250, 300, 45));
  ASSERT_TRUE(upper_arm.ok());
  EXPECT_NEAR(upper_arm->value_mm, 2 * M_PI * 40, 2.0);
  EXPECT_EQ(cloud_girth(cloud, horizontal(900), std::nullopt).status().code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace bodyscan
