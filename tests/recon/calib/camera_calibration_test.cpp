#include "recon/calib/camera_calibration.hpp"

#include <gtest/gtest.h>

namespace bodyscan {
namespace {

// A front camera's markers: per frame the near pair (farther from the horizon,
// wider apart) outside the far pair.
FrameMarkers front_markers() {
  FrameMarkers m;
  m.top = {Eigen::Vector2d(300, 40), Eigen::Vector2d(420, 150), Eigen::Vector2d(860, 150), Eigen::Vector2d(980, 40)};
  m.bottom = {Eigen::Vector2d(300, 980), Eigen::Vector2d(420, 860), Eigen::Vector2d(860, 860),
              Eigen::Vector2d(980, 980)};
  return m;
}

Marker at(double x, double y) {
  Marker k;
  k.centre = {x, y};
  k.area = 50;
  return k;
}

TEST(CameraSide, FrontLightsLightTheNearPairsOfAFrontCamera) {
  const FrameMarkers m = front_markers();
  auto side = identify_side(m, {at(300, 40), at(980, 40), at(300.5, 980), at(980, 979)});
  ASSERT_TRUE(side.ok()) << side.status().message();
  EXPECT_EQ(*side, FrameSide::kFront);
  side = identify_side(m, {at(420, 150), at(860, 150), at(420, 860), at(860, 860)});
  ASSERT_TRUE(side.ok());
  EXPECT_EQ(*side, FrameSide::kBack);
  side = identify_side(m, {at(420, 150), at(300, 40)});
  ASSERT_FALSE(side.ok());
  EXPECT_NE(side.status().message().find("wiring"), std::string::npos) << side.status().message();
}

TEST(CameraSide, MarkersAreNamedByPoleAndWorldX) {
  const FrameMarkers m = front_markers();
  auto front = name_markers(m, FrameSide::kFront);
  EXPECT_EQ(front[static_cast<size_t>(Pole::kNearTop)][0], Eigen::Vector2d(300, 40));
  EXPECT_EQ(front[static_cast<size_t>(Pole::kFarBottom)][1], Eigen::Vector2d(860, 860));
  // Seen from the back, image left is world +X.
  auto back = name_markers(m, FrameSide::kBack);
  EXPECT_EQ(back[static_cast<size_t>(Pole::kNearTop)][0], Eigen::Vector2d(980, 40));
  EXPECT_EQ(back[static_cast<size_t>(Pole::kFarBottom)][0], Eigen::Vector2d(860, 860));
}

TEST(ReferenceFrameGeometry, FacesAndLights) {
  const ReferenceFrame f;
  EXPECT_DOUBLE_EQ(f.face_z(Pole::kNearBottom, FrameSide::kFront), 570);
  EXPECT_DOUBLE_EQ(f.face_z(Pole::kFarTop, FrameSide::kFront), -530);
  EXPECT_DOUBLE_EQ(f.face_z(Pole::kNearTop, FrameSide::kBack), -570);
  EXPECT_EQ(f.light(Pole::kFarTop, FrameSide::kBack, 1), Eigen::Vector3d(700, 2300, 530));
}

}  // namespace
}  // namespace bodyscan
