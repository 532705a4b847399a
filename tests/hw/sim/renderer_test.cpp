#include "hw/sim/renderer.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace bodyscan::hw::sim {
namespace {

// A rig with one camera in front of the frame and one laser beside it, no subject
// description beyond what the tests pass in.
RigDescription test_rig() {
  RigDescription rig;
  rig.name = "test";
  CameraDescription c;
  c.id = "cam";
  c.position = Vec3d(-300, 1000, 2500);
  c.look_at = Vec3d(0, 1000, 0);
  c.focal_mm = 8;
  c.pixel_size_um = 5.3;
  c.width = 320;
  c.height = 256;
  c.distortion = {-0.1, 0.02, 0, 0.0003, -0.0002};
  rig.cameras.push_back(c);
  LaserDescription l;
  l.id = "laser";
  l.position = Vec3d(400, 1000, 2000);
  l.aim = Vec3d(-0.2, 0, -1).normalized();
  l.step_angle_deg = 0.1;
  l.min_step = -50;
  l.max_step = 50;
  l.line_width_mm = 2.0;
  rig.lasers.push_back(l);
  rig.laser_groups = {{"laser"}};
  rig.simulation.speckle_contrast = 0;
  return rig;
}

// A wall: the plane z = z0, x and y in [-w, w] x [0, 2 w] before standing on the floor.
void add_quad(TriangleMesh& m, const Vec3f& a, const Vec3f& b, const Vec3f& c, const Vec3f& d) {
  const uint32_t o = static_cast<uint32_t>(m.vertices.size());
  m.vertices.insert(m.vertices.end(), {a, b, c, d});
  m.triangles.push_back({o, o + 1, o + 2});
  m.triangles.push_back({o, o + 2, o + 3});
}

TriangleMesh wall(float z0) {
  TriangleMesh m;
  add_quad(m, {-1000, 0, z0}, {1000, 0, z0}, {1000, 2000, z0}, {-1000, 2000, z0});
  return m;
}

TEST(Renderer, StripeOnAPlaneIsWhereGeometrySaysToAHundredthOfAPixel) {
  const RigDescription rig = test_rig();
  auto scene = Scene::create(rig, wall(0));
  ASSERT_TRUE(scene.ok()) << scene.status().message();
  const Renderer r(rig.cameras[0], rig.simulation);
  Lighting lit;
  lit.lasers.push_back({&rig.lasers[0], 13});
  const std::vector<float> on = r.irradiance(**scene, lit);
  const std::vector<float> off = r.irradiance(**scene, Lighting{});
  const LaserDescription& l = rig.lasers[0];
  const Vec3d n = l.plane_normal(13);
  const double d = l.plane_offset(13);
  // The true stripe: the laser plane meets the wall (z = 0 after standing: the wall
  // is centred) in a vertical line; its image crosses each row once.
  const double wall_z = (**scene).subject().vertices[0].z();
  double ss = 0;
  int rows = 0;
  const int w = r.model().width();
  for (int y = 20; y < r.model().height() - 20; ++y) {
    int best = -1;
    float peak = 0;
    for (int x = 0; x < w; ++x) {
      const float v = on[y * w + x] - off[y * w + x];
      if (v > peak) peak = v, best = x;
    }
    ASSERT_GT(peak, 0.05f) << "row " << y;
    double sw = 0, sx = 0;
    for (int x = std::max(0, best - 6); x <= std::min(w - 1, best + 6); ++x) {
      const double v = on[y * w + x] - off[y * w + x];
      sw += v;
      sx += v * x;
    }
    const double measured = sx / sw;
    // Where the true line crosses this row: bisect on the 3-D line's height.
    auto pixel_at = [&](double height) {
      // Point on the plane n.p = d with z = wall_z, y = height.
      const double x3 = (d - n.y() * height - n.z() * wall_z) / n.x();
      return *r.model().project(Vec3d(x3, height, wall_z));
    };
    double lo = -500, hi = 2500;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      if (pixel_at(mid).y() > y) lo = mid; else hi = mid;  // image y grows downward
    }
    const double expected = pixel_at(0.5 * (lo + hi)).x();
    ss += (measured - expected) * (measured - expected);
    ++rows;
  }
  const double rms = std::sqrt(ss / rows);
  EXPECT_LT(rms, 0.05) << "px RMS over " << rows << " rows";
  std::printf("[ stripe ] %.4f px RMS over %d rows (centroid of the noise-free profile)\n", rms, rows);
}

TEST(Renderer, BoxBeforeAWallCastsALaserShadowAndHidesTheWall) {
  RigDescription rig = test_rig();
  TriangleMesh m = wall(0);
  // A 200 mm box 600 mm in front of the wall, between it and the laser.
  const float z1 = 700, x0 = -50, x1 = 150, y0 = 800, y1 = 1100;
  add_quad(m, {x0, y0, z1}, {x1, y0, z1}, {x1, y1, z1}, {x0, y1, z1});  // front face (+z)
  auto scene = Scene::create(rig, m);
  ASSERT_TRUE(scene.ok());
  // Step so the plane passes through the box.
  const LaserDescription& l = rig.lasers[0];
  int step = 0;
  double best = 1e9;
  const double shift = (**scene).subject().vertices[4].x() - x0;  // where standing moved the box
  for (int s = l.min_step; s <= l.max_step; ++s) {
    const double box_z = (**scene).subject().vertices[4].z();
    const double x_at_box = (l.plane_offset(s) - l.plane_normal(s).y() * 1000 - l.plane_normal(s).z() * box_z) /
                            l.plane_normal(s).x();
    const double miss = std::abs(x_at_box - (shift + 0.5 * (x0 + x1)));
    if (miss < best) best = miss, step = s;
  }
  const Renderer r(rig.cameras[0], rig.simulation);
  Lighting lit;
  lit.lasers.push_back({&l, step});
  const std::vector<float> on = r.irradiance(**scene, lit);
  const std::vector<float> off = r.irradiance(**scene, Lighting{});
  const int w = r.model().width(), h = r.model().height();
  size_t lit_wall = 0, shadowed_wall = 0, lit_box = 0;
  const Vec3d laser_n = l.plane_normal(step);
  const double box_z = (**scene).subject().vertices[4].z();
  for (int y = 0; y < h; ++y) {
    // Per row and surface, the pixel whose surface point is nearest the laser plane:
    // the stripe's centre there (the stripe is about one pixel wide).
    for (const bool want_box : {true, false}) {
      int best_x = -1;
      double best_dist = 1.5;  // mm; the pixel footprint is about 1.4 mm
      Hit best_hit;
      for (int x = 0; x < w; ++x) {
        const Hit hit = r.surface_at(**scene, Vec2d(x, y));
        if (hit.surface != Surface::kSubject) continue;
        if ((std::abs(hit.position.z() - box_z) < 1) != want_box) continue;
        const double dist = std::abs(laser_n.dot(hit.position) - l.plane_offset(step));
        if (dist < best_dist) best_dist = dist, best_x = x, best_hit = hit;
      }
      if (best_x < 0) continue;
      const float laser = on[y * w + best_x] - off[y * w + best_x];
      if (want_box) {
        lit_box += laser > 0.1f;
        continue;
      }
      const Vec3d to_laser = l.position - best_hit.position;
      if ((**scene).occluded(best_hit.position + 0.05 * best_hit.normal, to_laser.normalized(), to_laser.norm())) {
        EXPECT_EQ(laser, 0.f) << "shadowed wall pixel " << best_x << "," << y;
        ++shadowed_wall;
      } else {
        lit_wall += laser > 0.1f;
      }
    }
  }
  EXPECT_GT(lit_box, 10u);
  EXPECT_GT(lit_wall, 10u);
  EXPECT_GT(shadowed_wall, 10u);  // the shadow is there and dark
  // The camera does not see the wall through the box: the box's face is what the
  // centre ray through it hits.
  const auto box_centre_px = r.model().project(Vec3d(shift + 0.5 * (x0 + x1), (**scene).subject().vertices[4].y() + 150, (**scene).subject().vertices[4].z()));
  ASSERT_TRUE(box_centre_px);
  EXPECT_NEAR(r.surface_at(**scene, *box_centre_px).position.z(), (**scene).subject().vertices[4].z(), 1e-3);
}

TEST(Renderer, FrameLightsAndNoiseAreDeterministic) {
  RigDescription rig = test_rig();
  rig.frame.width = 1800;
  rig.frame.depth = 1100;
  rig.frame.top_height = 2300;
  rig.frame.light_x = {-250, 250};
  // Looking down at the bottom frame's front pole.
  rig.cameras[0].position = Vec3d(0, 300, 2500);
  rig.cameras[0].look_at = Vec3d(0, 0, 570);
  rig.cameras[0].focal_mm = 4;
  auto scene = Scene::create(rig, TriangleMesh{});
  ASSERT_TRUE(scene.ok());
  const Renderer r(rig.cameras[0], rig.simulation);
  Lighting lights;
  lights.front_frame_lights = lights.back_frame_lights = true;
  const Frame a = r.render(**scene, lights, {}, 7), b = r.render(**scene, lights, {}, 7), c = r.render(**scene, lights, {}, 8);
  EXPECT_EQ(a.pixels, b.pixels);
  EXPECT_NE(a.pixels, c.pixels);  // noise differs frame to frame
  // Every front light in view is bright at its centre (saturated: frame_light 1.5
  // is above full scale) and dark with the lights off.
  const Frame dark = r.render(**scene, Lighting{}, {}, 7);
  int seen = 0;
  for (double ly : {0.0, rig.frame.top_height})
    for (double lx : rig.frame.light_x) {
      const auto p = r.model().project(Vec3d(lx, ly, 0.5 * rig.frame.depth + 0.5 * rig.frame.tube));
      if (!p || p->x() < 3 || p->y() < 3 || p->x() > a.width - 4 || p->y() > a.height - 4) continue;
      const int px = static_cast<int>(std::lround(p->x())), py = static_cast<int>(std::lround(p->y()));
      EXPECT_EQ(a.at(px, py), 255) << lx << "," << ly;
      EXPECT_LT(dark.at(px, py), 40) << lx << "," << ly;
      ++seen;
    }
  EXPECT_GE(seen, 1);
}

}  // namespace
}  // namespace bodyscan::hw::sim
