#include "recon/measure/body_frame.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "recon/io/ply.hpp"
#include "recon/measure/body_measurements.hpp"
#include "tests/test_meshes.hpp"

namespace bodyscan {
namespace {

const TriangleMesh& demo_body() {
  static const TriangleMesh mesh = [] {
    auto m = read_ply_mesh(BODYSCAN_SOURCE_DIR "/hw/sim/bodies/female_average.ply");
    EXPECT_TRUE(m.ok());
    return m.ok() ? *m : TriangleMesh{};
  }();
  return mesh;
}

// Turned about the vertical by `deg` (the face from +Z toward +X), then moved.
Eigen::Isometry3d motion(double deg, const Eigen::Vector3d& shift) {
  return Eigen::Translation3d(shift) * Eigen::AngleAxisd(deg * M_PI / 180, Eigen::Vector3d::UnitY());
}

double angle_difference(double a, double b) { return std::remainder(a - b, 360.0); }

TEST(BodyFrame, FindsWhichWayTheBodyFacesAndWhereItStands) {
  auto rest = find_body_frame(demo_body());
  ASSERT_TRUE(rest.ok()) << rest.status().message();
  // The shipped body faces +Z, its left at +X, its trunk over the origin.
  EXPECT_NEAR(rest->turn_deg, 0, 0.05);
  EXPECT_LT(rest->asymmetry_rms_mm, 0.5);  // MakeHuman's bodies are mirror-symmetric
  EXPECT_GT(rest->feet_forward_mm, 20);
  EXPECT_NEAR(rest->world_from_body.translation().x(), 0, 0.5);
  EXPECT_NEAR(rest->floor_y, 0, 1e-3);
  for (double deg : {-179.0, -90.0, -30.0, 12.5, 30.0, 135.0, 180.0}) {
    const Eigen::Vector3d shift(250, 0, -180);
    const Eigen::Isometry3d m = motion(deg, shift);
    auto f = find_body_frame(transformed(demo_body(), m));
    ASSERT_TRUE(f.ok()) << f.status().message();
    EXPECT_NEAR(angle_difference(f->turn_deg, rest->turn_deg + deg), 0, 0.05) << deg;
    // The frame moved with the body: the same body point in either frame.
    const Eigen::Vector3d p(120, 900, 40);
    EXPECT_LT((f->body_from_world() * (m * p) - rest->body_from_world() * p).norm(), 0.2) << deg;
  }
}

TEST(BodyFrame, ARigidMotionChangesNoMeasurement) {
  auto rest = measure_body(demo_body());
  ASSERT_TRUE(rest.ok()) << rest.status().message();
  for (double deg : {-30.0, 20.0, 90.0}) {
    const Eigen::Isometry3d m = motion(deg, {300, 0, 150});
    auto moved = measure_body(transformed(demo_body(), m));
    ASSERT_TRUE(moved.ok()) << moved.status().message();
    ASSERT_EQ(moved->measurements.size(), rest->measurements.size());
    for (const BodyMeasurement& a : rest->measurements) {
      const BodyMeasurement* b = moved->find(a.name);
      ASSERT_NE(b, nullptr) << a.name;
      EXPECT_NEAR(b->value_mm, a.value_mm, 0.1) << a.name << " turned " << deg;
      // The geometry comes back in the mesh's own frame.
      ASSERT_FALSE(b->path.empty());
      EXPECT_LT((b->path.front() - m * a.path.front()).norm(), 0.5) << a.name;
    }
    for (const BodyLandmark& a : rest->landmarks)
      EXPECT_LT((moved->landmark(a.name)->position - m * a.position).norm(), 0.5) << a.name << " turned " << deg;
  }
}

TEST(BodyFrame, RefusesWhatIsNoStandingBody) {
  EXPECT_FALSE(find_body_frame(TriangleMesh{}).ok());
  EXPECT_FALSE(find_body_frame(testing::icosphere(3, 100)).ok());  // 200 mm tall
}

}  // namespace
}  // namespace bodyscan
