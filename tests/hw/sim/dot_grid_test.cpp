#include "hw/sim/dot_grid.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace bodyscan::hw::sim {
namespace {

TEST(DotGrid, DotsImageWhereTheLensModelSays) {
  CameraDescription c;
  c.id = "cam";
  c.position = Vec3d(0, 1000, 2500);
  c.look_at = Vec3d(0, 1000, 0);
  c.focal_mm = 4.8;
  c.pixel_size_um = 5.3 * 2;
  c.width = 640;
  c.height = 512;
  c.distortion = {-0.12, 0.03, 0, 0.0004, -0.0003};
  SimulationDescription sim;
  const CameraModel m = c.model();
  const DotGridTarget target = dot_grid_for(m);
  const Frame f = render_dot_grid(c, sim, target, 1);
  const std::vector<DotTruth> truth = dot_grid_truth(m, target);
  // Dot spacing in pixels near the centre: about 640 / 25.
  const double spacing_px = m.width() / 25.0;
  const int r = static_cast<int>(0.35 * spacing_px);
  int checked = 0;
  double worst = 0, sum2 = 0;
  for (const DotTruth& d : truth) {
    if (!d.in_image || d.pixel.x() < r + 2 || d.pixel.y() < r + 2 || d.pixel.x() > m.width() - r - 3 ||
        d.pixel.y() > m.height() - r - 3)
      continue;
    // Darkness-weighted centroid around the true centre (white ~ 0.9 * 0.6 of full scale).
    const int cx = static_cast<int>(std::lround(d.pixel.x())), cy = static_cast<int>(std::lround(d.pixel.y()));
    double sw = 0, sx = 0, sy = 0;
    const double white = 0.9 * sim.room_light * 255;
    for (int y = cy - r; y <= cy + r; ++y)
      for (int x = cx - r; x <= cx + r; ++x) {
        const double dark = std::max(0.0, white - f.at(x, y));
        sw += dark;
        sx += dark * x;
        sy += dark * y;
      }
    ASSERT_GT(sw, 0) << d.col << "," << d.row;
    const double err = (Vec2d(sx / sw, sy / sw) - d.pixel).norm();
    worst = std::max(worst, err);
    sum2 += err * err;
    ++checked;
  }
  EXPECT_GT(checked, 300);
  // The centroid of a dot's image is not exactly the image of its centre (perspective
  // and distortion skew it), but at these sizes the two agree to a tenth of a pixel.
  EXPECT_LT(std::sqrt(sum2 / checked), 0.1);
  EXPECT_LT(worst, 0.3);
  std::printf("[ dots ] %d dots, centroid vs projected centre: RMS %.3f px, worst %.3f px\n", checked,
              std::sqrt(sum2 / checked), worst);
}

TEST(DotGrid, TargetFacesTheCameraAndIsTurned) {
  const CameraModel m = CameraModel::look_at(640, 480, 8, 0.01, {}, Vec3d(0, 0, 0), Vec3d(0, 0, 1000));
  const DotGridTarget t = dot_grid_for(m, 800, 25, 4);
  EXPECT_NEAR((t.centre - Vec3d(0, 0, 800)).norm(), 0.0, 1e-9);
  EXPECT_NEAR(std::abs(t.u.cross(t.v).dot(m.world_from_camera().col(2))), 1.0, 1e-12);
  EXPECT_NEAR(std::acos(t.u.dot(m.world_from_camera().col(0))) * 180 / M_PI, 4.0, 1e-9);
}

}  // namespace
}  // namespace bodyscan::hw::sim
