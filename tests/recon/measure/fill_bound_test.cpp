// How far filled-in skin could move a value, against the geometry worked out by
// hand: an arc's excess over its chord, a bump's over its base, a cap's height.
#include "recon/measure/fill_bound.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "recon/io/ply.hpp"
#include "recon/measure/body_measurements.hpp"
#include "recon/measure/girth.hpp"
#include "tests/shapes.hpp"

namespace bodyscan {
namespace {

// A circle of radius r in the XZ plane, n points, those within `filled` radians of
// +X (either way) filled in.
void circle_loop(double r, int n, double filled, std::vector<Eigen::Vector3d>* points, std::vector<float>* confidence) {
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    points->emplace_back(r * std::cos(a), 0, r * std::sin(a));
    const double from_x = std::min(a, 2 * M_PI - a);
    confidence->push_back(from_x < filled ? 0.f : 1.f);
  }
}

TEST(FillBound, AFilledArcOfALoopCountsItsExcessOverTheChord) {
  for (int start : {0, 100}) {  // the filled arc at the loop's start, and inside it
    std::vector<Eigen::Vector3d> p;
    std::vector<float> c;
    circle_loop(150, 3600, 0.5, &p, &c);
    std::rotate(p.begin(), p.begin() + start, p.end());
    std::rotate(c.begin(), c.begin() + start, c.end());
    // The seen points either side are 0.5 rad (plus under one step) from +X: an arc of
    // about 1 rad, 150 mm round, over a chord 2 r sin(0.5).
    const double step = 2 * M_PI / 3600;
    const double theta = 2 * (std::ceil(0.5 / step) * step);
    const double expected = 150 * theta - 2 * 150 * std::sin(theta / 2);
    const auto excess = filled_stretch_excess_mm(p, c, true);
    ASSERT_TRUE(excess.has_value());
    EXPECT_NEAR(*excess, expected, 0.01) << start;
    EXPECT_GT(*excess, 6.0);  // a flank-sized gap is worth flagging
  }
}

TEST(FillBound, SeenSkinAndAStraightFillCountNothing) {
  std::vector<Eigen::Vector3d> p;
  std::vector<float> c;
  circle_loop(150, 720, 0, &p, &c);
  EXPECT_EQ(*filled_stretch_excess_mm(p, c, true), 0);
  // An open straight line with its middle filled: the fill is its own chord.
  std::vector<Eigen::Vector3d> line;
  std::vector<float> conf;
  for (int i = 0; i <= 10; ++i) line.emplace_back(10.0 * i, 0, 0), conf.push_back(i > 3 && i < 8 ? 0.f : 1.f);
  EXPECT_NEAR(*filled_stretch_excess_mm(line, conf, false), 0, 1e-9);
}

TEST(FillBound, AnOpenPathCountsAFilledBumpAndAFilledEnd) {
  // Along X with a triangular bump 30 mm high over a 40 mm base, filled.
  std::vector<Eigen::Vector3d> p = {{0, 0, 0}, {40, 0, 0}, {60, 30, 0}, {80, 0, 0}, {120, 0, 0}};
  std::vector<float> c = {1, 1, 0, 1, 1};
  EXPECT_NEAR(*filled_stretch_excess_mm(p, c, false), 2 * std::hypot(20.0, 30.0) - 40, 1e-9);
  // The path's last stretch filled, running off its end: measured from that end.
  std::vector<Eigen::Vector3d> q = {{0, 0, 0}, {40, 0, 0}, {60, 30, 0}, {80, 0, 0}};
  std::vector<float> d = {1, 1, 0, 0};
  EXPECT_NEAR(*filled_stretch_excess_mm(q, d, false), 2 * std::hypot(20.0, 30.0) - 40, 1e-9);
  // Nothing seen: the whole length. Confidences that do not match: not known.
  EXPECT_NEAR(*filled_stretch_excess_mm(q, {0, 0, 0, 0}, false), 40 + 2 * std::hypot(20.0, 30.0), 1e-9);
  EXPECT_FALSE(filled_stretch_excess_mm(q, {1, 1}, false).has_value());
}

TEST(FillBound, ALandmarkOnAFilledCapIsAsFarAsTheCapRisesAboveTheSeenSkin) {
  // A cylinder 1000 mm tall, its top 40 mm filled: the centre of the top cap lies
  // 40 mm above the highest seen ring.
  TriangleMesh m = testing::prism(testing::circle(100), {0, 0}, 0, 1000, 25);
  m.confidence.assign(m.vertices.size(), 1.f);
  for (size_t i = 0; i < m.vertices.size(); ++i)
    if (m.vertices[i].y() > 961) m.confidence[i] = 0.f;
  const Eigen::Vector3d top(0, 1000, 0);
  EXPECT_NEAR(landmark_fill_offset_mm(m, top, Eigen::Vector3d::UnitY()), 40, 1e-3);
  // Sideways the nearest seen skin is 100 mm out.
  EXPECT_NEAR(landmark_fill_offset_mm(m, top, Eigen::Vector3d::UnitX()), 100, 1.0);
  // On seen skin: nothing.
  EXPECT_EQ(landmark_fill_offset_mm(m, Eigen::Vector3d(100, 500, 0), Eigen::Vector3d::UnitY()), 0);
}

TEST(FillBound, AGirthRoundAFilledFlankIsAnEstimateByItsExcess) {
  // A prism of radius 150 with the +X flank (within 0.5 rad) filled: the tape at
  // mid-height is the circle's, and the fill bound the arc's excess over its chord.
  TriangleMesh m = testing::prism(testing::circle(150, {0, 0}, 720), {0, 0}, 0, 400, 8);
  m.confidence.assign(m.vertices.size(), 1.f);
  for (size_t i = 0; i < m.vertices.size(); ++i)
    if (std::abs(std::atan2(m.vertices[i].z(), m.vertices[i].x())) < 0.5) m.confidence[i] = 0.f;
  auto g = mesh_girth(m, Plane{Eigen::Vector3d(0, 200, 0), Eigen::Vector3d::UnitY()});
  ASSERT_TRUE(g.ok());
  ASSERT_TRUE(g->fill_bound_mm.has_value());
  // Between the last seen vertices either side: just over 1 rad of arc.
  const double step = 2 * M_PI / 720, theta = 2 * std::ceil(0.5 / step) * step;
  EXPECT_NEAR(*g->fill_bound_mm, 150 * theta - 2 * 150 * std::sin(theta / 2), 0.2);
}

// The shipped body, measured as seen in full, then with its crown and its right
// flank filled in: only the values over the filled skin become estimates, each by
// how far that skin could move it.
TEST(FillBound, OnABodyOnlyTheValuesOverTheFilledSkinAreEstimates) {
  auto mesh = read_ply_mesh(BODYSCAN_SOURCE_DIR "/hw/sim/bodies/female_average.ply");
  ASSERT_TRUE(mesh.ok());
  TriangleMesh body = *mesh;
  body.confidence.assign(body.vertices.size(), 1.f);
  auto seen = measure_body(body);
  ASSERT_TRUE(seen.ok());
  for (const BodyMeasurement& m : seen->measurements) {
    EXPECT_FALSE(m.estimated()) << m.name;
    ASSERT_TRUE(m.fill_bound_mm.has_value()) << m.name;
    EXPECT_EQ(*m.fill_bound_mm, 0) << m.name;
  }

  // The top 25 mm of the head unseen.
  float top = -1e9f;
  for (const Vec3f& v : body.vertices) top = std::max(top, v.y());
  for (size_t i = 0; i < body.vertices.size(); ++i)
    if (body.vertices[i].y() > top - 25) body.confidence[i] = 0.f;
  auto capped = measure_body(body);
  ASSERT_TRUE(capped.ok());
  const BodyMeasurement* stature = capped->find("stature");
  ASSERT_NE(stature, nullptr);
  EXPECT_TRUE(stature->estimated());
  ASSERT_TRUE(stature->fill_bound_mm.has_value());
  EXPECT_NEAR(*stature->fill_bound_mm, 25, 3) << "the crown stands this far above the highest seen skin";
  for (const char* untouched : {"waist_girth", "hip_girth", "crotch_height", "thigh_girth_left"}) {
    const BodyMeasurement* m = capped->find(untouched);
    ASSERT_NE(m, nullptr) << untouched;
    EXPECT_FALSE(m->estimated()) << untouched;
  }
}

}  // namespace
}  // namespace bodyscan
