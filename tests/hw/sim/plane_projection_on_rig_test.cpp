// The image-to-frame-plane transforms (recon/calib) from a camera's eight frame
// lights, and the two-plane ray, against the true camera (lens distortion off: the
// lens correction comes first in the pipeline).
#include <gtest/gtest.h>

#include <random>

#include "hw/rig_description.hpp"
#include "recon/calib/plane_projection.hpp"

namespace bodyscan::hw {
namespace {

TEST(PlaneProjectionOnRig, FromTheEightLightsToEveryPixelsRay) {
  auto desc = load_rig_description(*shipped_rig_path("thesis"));
  ASSERT_TRUE(desc.ok());
  CameraDescription cam = desc->cameras[0];
  cam.distortion = {};
  const CameraModel m = cam.model();
  const FrameGeometry& f = desc->frame;
  // The four lights the camera sees on each frame: the near pole's outer ones and
  // the far pole's inner ones, corners of a rectangle in the frame's plane.
  std::vector<Eigen::Vector2d> top_px, bottom_px, xz;
  for (const Vec3d& l : visible_lights(f, true)) {
    if (l.y() > 0) {
      top_px.push_back(*m.project(l));
      xz.emplace_back(l.x(), l.z());
    } else {
      bottom_px.push_back(*m.project(l));
    }
  }
  auto top = PlaneProjection::fit(top_px, xz, f.top_height);
  auto bottom = PlaneProjection::fit(bottom_px, xz, 0.0);
  ASSERT_TRUE(top.ok()) << top.status().message();
  ASSERT_TRUE(bottom.ok()) << bottom.status().message();
  EXPECT_LT(top->residual_px(), 1e-6);
  // Every world point inside the frame lies on its pixel's two-plane ray, and every
  // ray passes through the camera's centre, which nobody told the fit.
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> ux(-800, 800), uy(0, 2300), uz(-500, 500);
  double worst = 0, worst_centre = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3d p(ux(rng), uy(rng), uz(rng));
    const auto px = m.project(p);
    ASSERT_TRUE(px);
    const Ray3 r = two_plane_ray(*top, *bottom, *px);
    worst = std::max(worst, (p - r.origin).cross(r.direction).norm());
    worst_centre = std::max(worst_centre, (m.centre() - r.origin).cross(r.direction).norm());
  }
  EXPECT_LT(worst, 1e-6) << "mm";
  EXPECT_LT(worst_centre, 1e-6) << "mm";
  // The inverse projection (eq. 3.7) returns the pixel.
  EXPECT_LT((bottom->to_image(Eigen::Vector2d(123, -45)) - *m.project(Vec3d(123, 0, -45))).norm(), 1e-6);
}

TEST(PlaneProjectionOnRig, DegenerateInputIsRefused) {
  const std::vector<Eigen::Vector2d> line = {{0, 0}, {1, 1}, {2, 2}, {5, 1}};
  const std::vector<Eigen::Vector2d> xz = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  auto p = PlaneProjection::fit(line, xz, 0);
  ASSERT_FALSE(p.ok());
  EXPECT_NE(p.status().message().find("on one line"), std::string::npos);
  EXPECT_FALSE(PlaneProjection::fit({{0, 0}, {1, 0}, {0, 1}}, {{0, 0}, {1, 0}, {0, 1}}, 0).ok());
}

}  // namespace
}  // namespace bodyscan::hw
