#include "hw/camera_model.hpp"

#include <gtest/gtest.h>

#include <random>

namespace bodyscan::hw {
namespace {

CameraModel wide_lens() {
  // The thesis rig's front-left camera: 4.8 mm on 5.3 um pixels, barrel distortion.
  return CameraModel::look_at(1280, 1024, 4.8, 5.3e-3, {-0.12, 0.03, 0.001, 0.0004, -0.0003}, Vec3d(-900, 1150, 2700),
                              Vec3d(0, 1150, 0));
}

TEST(CameraModel, PinholeProjectionByHand) {
  // Camera at the origin looking along +Z with image y down = world -Y.
  const CameraModel m = CameraModel::look_at(640, 480, 8.0, 0.01, {}, Vec3d::Zero(), Vec3d(0, 0, 1000));
  EXPECT_DOUBLE_EQ(m.fx(), 800.0);
  EXPECT_DOUBLE_EQ(m.cx(), 319.5);
  const auto p = m.project(Vec3d(100, 50, 1000));
  ASSERT_TRUE(p);
  // Camera x = world -X here (x = y_cam x z_cam with y_cam = -Y, z_cam = +Z).
  EXPECT_NEAR(p->x(), 319.5 - 80.0, 1e-9);
  EXPECT_NEAR(p->y(), 239.5 - 40.0, 1e-9);    // above the axis -> smaller y (image y is down)
  EXPECT_FALSE(m.project(Vec3d(0, 0, -10)));  // behind the camera
}

TEST(CameraModel, DistortionIsTheOpenCvModel) {
  const Distortion d{-0.2, 0.05, 0.01, 0.001, -0.002};
  const CameraModel m(100, 100, 1, 1, 0, 0, d, Mat3d::Identity(), Vec3d::Zero());
  const double x = 0.3, y = -0.2, r2 = x * x + y * y;
  const double radial = 1 - 0.2 * r2 + 0.05 * r2 * r2 + 0.01 * r2 * r2 * r2;
  const Vec2d expect(x * radial + 2 * 0.001 * x * y - 0.002 * (r2 + 2 * x * x),
                     y * radial + 0.001 * (r2 + 2 * y * y) + 2 * -0.002 * x * y);
  EXPECT_NEAR((m.distort({x, y}) - expect).norm(), 0.0, 1e-15);
}

TEST(CameraModel, RayAndProjectionRoundTripToAHundredthOfAPixel) {
  const CameraModel m = wide_lens();
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-0.5, 1279.5), v(-0.5, 1023.5), dist(500, 5000);
  double worst = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec2d pixel(u(rng), v(rng));
    const auto ray = m.ray(pixel);
    ASSERT_TRUE(ray) << pixel.transpose();
    EXPECT_NEAR(ray->norm(), 1.0, 1e-12);
    const auto back = m.project(m.centre() + dist(rng) * *ray);
    ASSERT_TRUE(back);
    worst = std::max(worst, (*back - pixel).norm());
  }
  EXPECT_LT(worst, 0.01);  // the projection tolerance; measured ~1e-9
  EXPECT_LT(worst, 1e-6);
}

TEST(CameraModel, LookAtIsLevelAndCentred) {
  const CameraModel m = wide_lens();
  const auto c = m.project(Vec3d(0, 1150, 0));
  ASSERT_TRUE(c);
  EXPECT_NEAR(c->x(), m.cx(), 1e-9);
  EXPECT_NEAR(c->y(), m.cy(), 1e-9);
  // A point straight above the target is above the centre on the image's centre column.
  const auto up = m.project(Vec3d(0, 1500, 0));
  ASSERT_TRUE(up);
  EXPECT_LT(up->y(), m.cy() - 50);
  EXPECT_NEAR(up->x(), m.cx(), 2.0);  // only distortion's tangential part moves it
  // The camera's x axis is horizontal (a level camera).
  EXPECT_NEAR(m.world_from_camera().col(0).y(), 0.0, 1e-12);
}

TEST(CameraModel, UndistortFailsCleanlyFarOutside) {
  const CameraModel m(100, 100, 1, 1, 0, 0, {-0.6, 0, 0, 0, 0}, Mat3d::Identity(), Vec3d::Zero());
  // The barrel's image radius peaks at r = 1/sqrt(3 * 0.6): beyond that no point maps there.
  EXPECT_FALSE(m.undistort({2.0, 0.0}));
  EXPECT_TRUE(m.undistort({0.3, 0.1}));
}

}  // namespace
}  // namespace bodyscan::hw
