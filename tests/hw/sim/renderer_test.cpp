#include "hw/sim/renderer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "recon/scan/stripe.hpp"

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
      if (pixel_at(mid).y() > y)
        lo = mid;
      else
        hi = mid;  // image y grows downward
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
    const double x_at_box =
        (l.plane_offset(s) - l.plane_normal(s).y() * 1000 - l.plane_normal(s).z() * box_z) / l.plane_normal(s).x();
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
  // Per row, the wall's stripe pixel: shadowed or not, and its laser light.
  std::vector<int> wall_x(static_cast<size_t>(h), -1);
  std::vector<char> in_shadow(static_cast<size_t>(h), 0);
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
      wall_x[static_cast<size_t>(y)] = best_x;
      in_shadow[static_cast<size_t>(y)] =
          (**scene).occluded(best_hit.position + 0.05 * best_hit.normal, to_laser.normalized(), to_laser.norm());
      if (!in_shadow[static_cast<size_t>(y)]) lit_wall += laser > 0.1f;
    }
  }
  // The shadow is dark, but for the lens's spread (3 pixels at 0.7 px) of the lit
  // stripe across its edges and of the box's own stripe, as a camera shows them.
  for (int y = 3; y + 3 < h; ++y) {
    const int x = wall_x[static_cast<size_t>(y)];
    if (x < 0 || !in_shadow[static_cast<size_t>(y)]) continue;
    bool inside = true;
    for (int dy = -3; dy <= 3; ++dy) inside = inside && in_shadow[static_cast<size_t>(y + dy)];
    for (int dy = -3; dy <= 3 && inside; ++dy)
      for (int dx = -3; dx <= 3 && inside; ++dx)
        inside = std::abs(r.surface_at(**scene, Vec2d(x + dx, y + dy)).position.z() - box_z) >= 1;
    if (!inside) continue;
    EXPECT_EQ(on[y * w + x] - off[y * w + x], 0.f) << "shadowed wall pixel " << x << "," << y;
    ++shadowed_wall;
  }
  EXPECT_GT(lit_box, 10u);
  EXPECT_GT(lit_wall, 10u);
  EXPECT_GT(shadowed_wall, 10u);  // the shadow is there and dark
  // The camera does not see the wall through the box: the box's face is what the
  // centre ray through it hits.
  const auto box_centre_px = r.model().project(
      Vec3d(shift + 0.5 * (x0 + x1), (**scene).subject().vertices[4].y() + 150, (**scene).subject().vertices[4].z()));
  ASSERT_TRUE(box_centre_px);
  EXPECT_NEAR(r.surface_at(**scene, *box_centre_px).position.z(), (**scene).subject().vertices[4].z(), 1e-3);
}

// A vertical cylinder of radius r about the Y axis from y0 to y1, n sides, closed.
TriangleMesh cylinder(float r, float y0, float y1, int n) {
  TriangleMesh m;
  for (int i = 0; i < n; ++i) {
    const float a = static_cast<float>(2 * M_PI * i / n);
    m.vertices.push_back({r * std::cos(a), y0, r * std::sin(a)});
    m.vertices.push_back({r * std::cos(a), y1, r * std::sin(a)});
  }
  const uint32_t bottom = static_cast<uint32_t>(m.vertices.size()), top = bottom + 1;
  m.vertices.push_back({0, y0, 0});
  m.vertices.push_back({0, y1, 0});
  for (int i = 0; i < n; ++i) {
    const uint32_t a = 2 * i, b = 2 * ((i + 1) % n);
    m.triangles.push_back({a, a + 1, b + 1});
    m.triangles.push_back({a, b + 1, b});
    m.triangles.push_back({bottom, a, b});
    m.triangles.push_back({top, b + 1, a + 1});
  }
  return m;
}

// The stripe on a limb-sized cylinder, extracted from the noise-free image as the
// scan does and met with the true laser plane, lies on the cylinder at every angle
// the camera sees it at, up to the silhouette. Shading each pixel from its centre
// ray alone (the profile widened by the footprint on the tangent plane, the lens's
// spread folded in) put the points seen at 75-90 degrees 0.6-1.6 mm inside a body
// (bench/stripe_fidelity), and made every girth of a rig that sees limbs edge-on
// come out small.
TEST(Renderer, AStripeSeenAtAGrazingAngleLiesOnTheSurface) {
  RigDescription rig = test_rig();
  rig.lasers[0].line_width_mm = 1.0;
  rig.cameras[0].distortion = {};
  auto scene = Scene::create(rig, cylinder(60, 0, 1400, 1440));
  ASSERT_TRUE(scene.ok()) << scene.status().message();
  // The axis where the scene stood the cylinder.
  Vec3d axis = Vec3d::Zero();
  for (const Vec3f& v : (**scene).subject().vertices) axis += v.cast<double>();
  axis /= static_cast<double>((**scene).subject().vertices.size());
  const Renderer r(rig.cameras[0], rig.simulation);
  const int w = r.model().width(), h = r.model().height();
  const LaserDescription& l = rig.lasers[0];
  const std::vector<float> off = r.irradiance(**scene, Lighting{});
  std::vector<double> frontal, grazing;
  for (int step = l.min_step; step <= l.max_step; step += 2) {
    Lighting lit;
    lit.lasers.push_back({&l, step});
    const std::vector<float> on = r.irradiance(**scene, lit);
    std::vector<uint16_t> px(on.size()), zero(on.size(), 0);
    for (size_t i = 0; i < on.size(); ++i)
      px[i] = static_cast<uint16_t>(std::clamp((on[i] - off[i]) * 20000.f, 0.f, 65535.f));
    auto samples = extract_stripe(ImageView{px.data(), w, h}, ImageView{zero.data(), w, h}, StripeOptions{}, 1 << 30);
    ASSERT_TRUE(samples.ok());
    const Vec3d n = l.plane_normal(step);
    for (const StripeSample& s : *samples) {
      const auto ray = r.model().ray(Vec2d(s.column, s.row));
      if (!ray) continue;
      const Vec3d p = r.model().centre() + ((l.plane_offset(step) - n.dot(r.model().centre())) / n.dot(*ray)) * *ray;
      if (p.y() < axis.y() - 400 || p.y() > axis.y() + 400) continue;  // clear of the caps
      Vec3d radial(p.x() - axis.x(), 0, p.z() - axis.z());
      const double err = radial.norm() - 60;
      if (std::abs(err) > 10) continue;  // the stripe on the floor or the frame
      const double view =
          std::acos(std::abs(radial.normalized().dot((r.model().centre() - p).normalized()))) * 180 / M_PI;
      (view < 45 ? frontal : view > 70 ? grazing : frontal).push_back(err);
    }
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  ASSERT_GT(frontal.size(), 500u);
  ASSERT_GT(grazing.size(), 100u);
  EXPECT_NEAR(median(frontal), 0, 0.05) << frontal.size() << " samples seen within 70 degrees";
  EXPECT_NEAR(median(grazing), 0, 0.15) << grazing.size() << " samples seen beyond 70 degrees";
  std::printf("[ grazing ] median radial error %+.3f mm within 70 degrees (%zu), %+.3f mm beyond (%zu)\n",
              median(frontal), frontal.size(), median(grazing), grazing.size());
}

// A swaying subject is cast again only where it was or could have come to be, and
// its room and frame lights are drawn again only there: the frame a renderer draws
// after the subject moved is the one a fresh renderer draws, to the bit, for a
// lighting last drawn at the pose before and for one last drawn poses ago, with the
// lens's blur and without.
TEST(Renderer, ASwayingSubjectIsRecastWhereItMovesAndNowhereElseChanges) {
  for (double blur : {0.7, 0.0}) {
    RigDescription rig = test_rig();
    rig.simulation.motion.sway_mm = 8;
    rig.simulation.motion.sway_hz = 0.25;
    rig.cameras[0].blur_px = blur;
    // Wide enough to see the bottom frame's front pole and its lights beside the subject.
    rig.cameras[0].focal_mm = 4;
    rig.cameras[0].look_at = Vec3d(0, 600, 0);
    auto scene = Scene::create(rig, cylinder(60, 0, 1400, 360));
    ASSERT_TRUE(scene.ok()) << scene.status().message();
    ASSERT_TRUE((**scene).moves());
    Lighting lit;
    lit.room_lights = true;
    lit.lasers.push_back({&rig.lasers[0], 4});
    Lighting framed = lit;
    framed.front_frame_lights = framed.back_frame_lights = true;
    const Renderer kept(rig.cameras[0], rig.simulation);
    const std::vector<float> at_rest = kept.irradiance(**scene, lit);
    const std::vector<float> framed_at_rest = kept.irradiance(**scene, framed);
    EXPECT_NE(at_rest, framed_at_rest) << "no frame light in view";
    int step = 0;
    for (double t : {1.0, 2.0, 0.3, 2.7}) {
      (**scene).set_time(t);
      const Renderer fresh(rig.cameras[0], rig.simulation);
      // The framed lighting is drawn every other pose only.
      const bool both = ++step % 2 == 0;
      const std::vector<float> a = kept.irradiance(**scene, lit), b = fresh.irradiance(**scene, lit);
      EXPECT_EQ(a, b) << "at " << t << " s, blur " << blur;
      EXPECT_NE(a, at_rest) << "at " << t << " s: the subject did not move";
      if (both) {
        EXPECT_EQ(kept.irradiance(**scene, framed), fresh.irradiance(**scene, framed))
            << "at " << t << " s, blur " << blur;
      }
    }
  }
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
  const Frame a = r.render(**scene, lights, {}, 7), b = r.render(**scene, lights, {}, 7),
              c = r.render(**scene, lights, {}, 8);
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
