#include "recon/scan/laser_sweep.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

namespace bodyscan {
namespace {

// A laser at (-500, 1150, 1900) turning about a slightly tilted vertical axis by
// 0.1 degrees a step; its pole points at four heights and depths, with noise.
struct TrueSweep {
  Eigen::Vector3d a{-500, 1150, 1900};
  Eigen::Vector3d u = Eigen::Vector3d(0.01, 1, -0.005).normalized();
  double theta0 = 0.3, dtheta = 0.1 * M_PI / 180;
  Eigen::Vector3d normal(int step) const {
    const Eigen::Vector3d e1 = u.cross(Eigen::Vector3d::UnitZ()).normalized(), e2 = u.cross(e1);
    const double t = theta0 + dtheta * step;
    return std::cos(t) * e1 + std::sin(t) * e2;
  }
  // The point of the step's plane at height y and depth z.
  Eigen::Vector3d point(int step, double y, double z) const {
    const Eigen::Vector3d n = normal(step);
    const double x = (n.dot(a) - n.y() * y - n.z() * z) / n.x();
    return {x, y, z};
  }
};

TEST(LaserSweep, RecoversTheAxisAndTheStepAngleFromNoisyPolePoints) {
  const TrueSweep truth;
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0, 0.2);
  std::vector<SweepPoint> points;
  std::vector<std::pair<int, SweepPlane>> planes;
  for (int step = -150; step <= 150; step += 3) {
    for (double y : {0.0, 2300.0})
      for (double z : {570.0, -530.0}) {
        Eigen::Vector3d p = truth.point(step, y, z);
        p.x() += noise(rng);
        points.push_back({step, p});
      }
    planes.push_back({step, {-truth.normal(step), -truth.normal(step).dot(truth.a)}});  // either sense
  }
  // A pole point the subject spoiled, 30 mm off.
  points[40].world.x() += 30;
  auto fit = LaserSweep::fit(points, planes);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  EXPECT_NEAR(std::abs(fit->degrees_per_step()), 0.1, 1e-4);
  EXPECT_EQ(fit->points_rejected(), 1u);
  EXPECT_LT(fit->rms_mm(), 0.25);
  // Each step's plane, where a body stands, against the truth: far better than one
  // frame's 0.2 mm points.
  for (int step : {-150, -37, 0, 90, 150}) {
    const SweepPlane p = fit->plane(step);
    for (double y : {200.0, 1700.0})
      for (double z : {-200.0, 200.0}) {
        const Eigen::Vector3d q = truth.point(step, y, z);
        EXPECT_LT(std::abs(p.normal.dot(q) - p.offset), 0.05) << "step " << step;
      }
  }
  // The fitted axis is the true one.
  const Eigen::Vector3d d = fit->axis_point() - truth.a;
  EXPECT_LT((d - d.dot(truth.u) * truth.u).norm(), 1.0);
  EXPECT_GT(std::abs(fit->axis_direction().dot(truth.u)), 0.9999);
}

TEST(LaserSweep, GrossOutliersAndAShortArcOfPolePointsStillGiveEveryPlane) {
  // A laser far to the side: its planes cross both poles over only part of its
  // sweep, one pole point in six is caught on the wrong face or a reflection
  // (50-400 mm off), and some frames' own planes, the fit's start, are badly wrong.
  const TrueSweep truth;
  std::mt19937 rng(9);
  std::normal_distribution<double> noise(0, 0.2);
  std::uniform_real_distribution<double> gross(50, 400);
  std::vector<SweepPoint> points;
  std::vector<std::pair<int, SweepPlane>> planes;
  size_t spoiled = 0;
  for (int step = -100; step <= 20; ++step) {
    for (double y : {0.0, 2300.0})
      for (double z : {570.0, -530.0}) {
        Eigen::Vector3d p = truth.point(step, y, z);
        p.x() += noise(rng);
        if (points.size() % 6 == 3) p.x() += gross(rng), ++spoiled;
        points.push_back({step, p});
      }
    Eigen::Vector3d n = truth.normal(step);
    if (step % 7 == 0) n = Eigen::AngleAxisd(0.08, Eigen::Vector3d::UnitY()) * n;  // 4.6 degrees off
    planes.push_back({step, {n, n.dot(truth.a) + (step % 5 == 0 ? 40.0 : 0.0)}});
  }
  auto fit = LaserSweep::fit(points, planes);
  ASSERT_TRUE(fit.ok()) << fit.status().message();
  EXPECT_NEAR(std::abs(fit->degrees_per_step()), 0.1, 2e-4);
  EXPECT_EQ(fit->points_rejected(), spoiled);
  // Planes where the body stands, within the arc and extrapolated 150 steps past it.
  for (int step : {-175, -60, 0, 100, 175}) {
    const SweepPlane p = fit->plane(step);
    for (double y : {200.0, 1700.0})
      for (double z : {-200.0, 200.0}) {
        const Eigen::Vector3d q = truth.point(step, y, z);
        EXPECT_LT(std::abs(p.normal.dot(q) - p.offset), 0.3) << "step " << step;
      }
  }
}

TEST(LaserSweep, TooFewStepsIsAnError) {
  const TrueSweep truth;
  std::vector<SweepPoint> points = {{0, truth.point(0, 0, 570)}, {1, truth.point(1, 0, 570)}};
  auto fit = LaserSweep::fit(points, {{0, {truth.normal(0), truth.normal(0).dot(truth.a)}}});
  EXPECT_FALSE(fit.ok());
}

}  // namespace
}  // namespace bodyscan
