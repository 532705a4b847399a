#include "recon/scan/view_angle.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace bodyscan {
namespace {

// A cylinder of radius 100 mm about the y axis, sampled every 1.5 mm, seen by one
// camera 3 m out on +z: the view angle of a point at azimuth phi (from +z) is phi
// plus the camera's parallax, atan(100 sin phi / (3000 - 100 cos phi)).
struct Cylinder {
  PointCloud cloud;
  std::vector<double> view_deg;  // true, per point
  std::vector<Vec3f> normal;     // true, per point
};

Cylinder cylinder_seen_from_front() {
  Cylinder c;
  const Vec3f camera(0, 0, 3000);
  c.cloud.camera_centres = {camera};
  for (double y = -60; y <= 60; y += 1.5)
    for (double phi = -88; phi <= 88; phi += 0.86) {
      const double a = phi * M_PI / 180;
      const Vec3f n(static_cast<float>(std::sin(a)), 0, static_cast<float>(std::cos(a)));
      const Vec3f p = 100.f * n + Vec3f(0, static_cast<float>(y), 0);
      c.cloud.positions.push_back(p);
      c.cloud.confidence.push_back(1.f);
      c.cloud.camera.push_back(0);
      c.cloud.laser.push_back(0);
      c.cloud.frame.push_back(static_cast<int>(y));
      c.view_deg.push_back(std::acos(n.dot((camera - p).normalized())) * 180 / M_PI);
      c.normal.push_back(n);
    }
  return c;
}

TEST(ViewAngle, GrazingPointsGoAndTheRestAreWeightedByHowSquarelyTheyAreSeen) {
  Cylinder c = cylinder_seen_from_front();
  const size_t n = c.cloud.size();
  // Mark each point by its true view angle in the intensity channel to follow it.
  c.cloud.intensity.assign(c.view_deg.begin(), c.view_deg.end());
  ViewAngleOptions o;  // drop beyond 70 degrees, full weight within 45
  const ViewAngleResult r = weigh_by_view_angle(c.cloud, o);
  EXPECT_TRUE(c.cloud.is_consistent());
  EXPECT_EQ(c.cloud.size() + r.dropped, n);
  size_t should_drop = 0;
  for (double v : c.view_deg) should_drop += v > 70;
  // Within one sample's azimuth of the true boundary (PCA normals are exact on a
  // cylinder away from its rim).
  EXPECT_NEAR(static_cast<double>(r.dropped), static_cast<double>(should_drop), 0.02 * static_cast<double>(n));
  ASSERT_EQ(c.cloud.normals.size(), c.cloud.size());
  for (size_t i = 0; i < c.cloud.size(); ++i) {
    const double view = c.cloud.intensity[i];
    EXPECT_LT(view, 71.0);
    // Normals face the camera and match the true ones within 2 degrees.
    const Vec3f truth(c.cloud.positions[i].x() / 100.f, 0, c.cloud.positions[i].z() / 100.f);
    EXPECT_GT(c.cloud.normals[i].dot(truth), std::cos(2 * M_PI / 180)) << "view " << view;
    // Confidence: 1 within 45 degrees, cos(view) / cos(45) beyond.
    const double expected = std::min(1.0, std::cos(view * M_PI / 180) / std::cos(M_PI / 4));
    EXPECT_NEAR(c.cloud.confidence[i], expected, 0.03) << "view " << view;
  }
}

TEST(ViewAngle, ACloudWithoutCamerasIsLeftAsItIs) {
  Cylinder c = cylinder_seen_from_front();
  c.cloud.camera_centres.clear();
  const size_t n = c.cloud.size();
  EXPECT_EQ(weigh_by_view_angle(c.cloud).dropped, 0u);
  EXPECT_EQ(c.cloud.size(), n);
  EXPECT_TRUE(c.cloud.normals.empty());
}

}  // namespace
}  // namespace bodyscan
