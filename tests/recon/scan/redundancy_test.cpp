#include "recon/scan/redundancy.hpp"

#include <gtest/gtest.h>

namespace bodyscan {
namespace {

PointCloud cloud_of(std::initializer_list<std::tuple<float, float, int>> pts) {  // x, confidence, frame
  PointCloud c;
  for (const auto& [x, conf, frame] : pts) {
    c.positions.emplace_back(x, 0.f, 0.f);
    c.confidence.push_back(conf);
    c.frame.push_back(frame);
    c.camera.push_back(0);
    c.laser.push_back(0);
  }
  return c;
}

TEST(RedundantPoints, TheBetterMeasurementStandsForThePlace) {
  PointCloud c = cloud_of({{0, 0.9f, 1}, {1, 0.3f, 2}, {10, 0.3f, 3}, {11, 0.5f, 4}, {20, 0.1f, 5}, {20.5f, 0.1f, 5}});
  EXPECT_EQ(drop_redundant_points(c, 2.f, 2.f), 1u);  // 1 (0.3) goes for 0 (0.9)
  ASSERT_EQ(c.size(), 5u);
  EXPECT_TRUE(c.is_consistent());
  // 10 (0.3) stays: 11 is better but not twice; 20 and 20.5 are one frame's samples.
  EXPECT_EQ(c.positions[1].x(), 10.f);
  // Weak points give way to any better point.
  EXPECT_EQ(drop_redundant_points(c, 2.f, 2.f, 0.4f), 1u);
  EXPECT_EQ(c.size(), 4u);
  for (const Vec3f& p : c.positions) EXPECT_NE(p.x(), 10.f);
}

TEST(RedundantPoints, WithoutConfidenceNothingGoes) {
  PointCloud c;
  c.positions = {Vec3f::Zero(), Vec3f::Zero()};
  EXPECT_EQ(drop_redundant_points(c, 1.f), 0u);
  EXPECT_EQ(c.size(), 2u);
}

}  // namespace
}  // namespace bodyscan
