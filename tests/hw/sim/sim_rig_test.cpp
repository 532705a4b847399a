#include "hw/sim/sim_rig.hpp"

#include <Eigen/Geometry>

#include "hw/sim/pose_body.hpp"

#include "recon/io/ply.hpp"

#include <gtest/gtest.h>

namespace bodyscan::hw::sim {
namespace {

std::unique_ptr<SimulatedRig> thesis_rig(int scale_down = 4) {
  auto path = shipped_rig_path("thesis");
  EXPECT_TRUE(path.ok());
  auto desc = load_rig_description(*path);
  EXPECT_TRUE(desc.ok()) << desc.status().message();
  // Quarter-resolution sensors (same field of view) keep the test quick.
  for (CameraDescription& c : desc->cameras) {
    c.width /= scale_down;
    c.height /= scale_down;
    c.pixel_size_um *= scale_down;
    c.blur_px /= scale_down;  // the same lens on bigger pixels
  }
  auto rig = SimulatedRig::create(*desc);
  EXPECT_TRUE(rig.ok()) << rig.status().message();
  return rig.ok() ? std::move(rig).value() : nullptr;
}

TEST(SimulatedRig, ControllerStepsLightsAndSafety) {
  auto rig = thesis_rig();
  ASSERT_TRUE(rig);
  Controller& c = rig->controller();
  EXPECT_EQ(c.num_lasers(), 4);
  EXPECT_EQ(c.move_to(0, 10).code(), StatusCode::kFailedPrecondition);  // not homed
  ASSERT_TRUE(c.home(0).ok());
  EXPECT_TRUE(c.move_to(0, 10).ok());
  EXPECT_EQ(*c.current_step(0), 10);
  const Status far = c.move_to(0, 100000);
  EXPECT_EQ(far.code(), StatusCode::kOutOfRange);
  EXPECT_NE(far.message().find("front-left"), std::string::npos) << far.message();
  EXPECT_EQ(c.set_laser(7, true).code(), StatusCode::kInvalidArgument);
  {
    LasersOff guard(c);
    ASSERT_TRUE(c.set_laser(0, true).ok());
    ASSERT_TRUE(c.set_laser(3, true).ok());
    EXPECT_TRUE(c.laser_on(0));
  }
  for (int i = 0; i < 4; ++i) EXPECT_FALSE(c.laser_on(i)) << "the guard switches every laser off";
}

TEST(SimulatedRig, GrabsFramesWithIdsTimesAndTheBodyLitByTheLaser) {
  auto rig = thesis_rig();
  ASSERT_TRUE(rig);
  Camera& cam = rig->camera(0);
  EXPECT_EQ(cam.info().id, "front-left");
  auto base = cam.grab();
  ASSERT_TRUE(base.ok()) << base.status().message();
  EXPECT_EQ(base->frame_id, 1u);
  EXPECT_EQ(base->width, 320);
  Controller& c = rig->controller();
  ASSERT_TRUE(c.home(0).ok());
  // Aim the front-left laser at the torso (x = -100 at the body's centre plane).
  const LaserDescription& l = rig->description().lasers[0];
  int step = 0;
  double miss = 1e9;
  for (int s = l.min_step; s <= l.max_step; ++s) {
    const double x = (l.plane_offset(s) - l.plane_normal(s).y() * 1150) / l.plane_normal(s).x();  // z = 0
    if (std::abs(x + 100) < miss) miss = std::abs(x + 100), step = s;
  }
  ASSERT_TRUE(c.move_to(0, step).ok());
  ASSERT_TRUE(c.set_laser(0, true).ok());
  auto lit = cam.grab();
  ASSERT_TRUE(lit.ok());
  EXPECT_EQ(lit->frame_id, 2u);
  EXPECT_GT(lit->timestamp_ns, base->timestamp_ns);
  // The stripe: many rows have a pixel far brighter than in the base frame, and the
  // surface under the brightest one lies on the laser's plane.
  int rows_with_stripe = 0;
  double worst_plane_distance = 0;
  for (int y = 0; y < lit->height; ++y) {
    int best = -1, peak = 0;
    for (int x = 0; x < lit->width; ++x) {
      const int d = lit->at(x, y) - base->at(x, y);
      if (d > peak) peak = d, best = x;
    }
    if (peak < 25) continue;
    ++rows_with_stripe;
    const Hit h = rig->renderer(0).surface_at(rig->scene(), Vec2d(best, y));
    ASSERT_NE(h.surface, Surface::kNone);
    worst_plane_distance =
        std::max(worst_plane_distance, std::abs(l.plane_normal(step).dot(h.position) - l.plane_offset(step)));
  }
  // The body spans about 140 of the 256 rows (the camera sees the whole frame);
  // the plane crosses the torso and a leg.
  EXPECT_GT(rows_with_stripe, 25);
  // Within a (quarter-resolution) pixel's footprint of the plane.
  EXPECT_LT(worst_plane_distance, 8.0);
  ASSERT_TRUE(c.all_lasers_off().ok());
}

TEST(SimulatedRig, CameraThatStopsAnsweringReportsIt) {
  auto rig = thesis_rig(8);
  ASSERT_TRUE(rig);
  rig->fail_camera_after(1, 2, StatusCode::kDeadlineExceeded);
  rig->fail_camera_after(2, 0, StatusCode::kUnavailable);
  EXPECT_TRUE(rig->camera(1).grab().ok());
  EXPECT_TRUE(rig->camera(1).grab().ok());
  auto third = rig->camera(1).grab(std::chrono::milliseconds(500));
  ASSERT_FALSE(third.ok());
  EXPECT_EQ(third.status().code(), StatusCode::kDeadlineExceeded);
  EXPECT_NE(third.status().message().find("front-right"), std::string::npos);
  EXPECT_NE(third.status().message().find("500 ms"), std::string::npos);
  auto gone = rig->camera(2).grab();
  ASSERT_FALSE(gone.ok());
  EXPECT_EQ(gone.status().code(), StatusCode::kUnavailable);
  EXPECT_TRUE(rig->camera(0).grab().ok());  // the others go on
}

TEST(SimulatedRig, PosesTurnsAndPlacesItsSubjectAsDescribed) {
  auto desc = load_rig_description(*shipped_rig_path("thesis"));
  ASSERT_TRUE(desc.ok());
  desc->simulation.posture.arm_abduction_deg = {20.0, 25.0};
  desc->simulation.posture.ankle_distance_mm = 250;
  desc->simulation.subject_yaw_deg = 30;
  desc->simulation.subject_offset = {120, 0, -80};
  auto rig = SimulatedRig::create(*desc);
  ASSERT_TRUE(rig.ok()) << rig.status().message();
  auto rest = read_ply_mesh(BODYSCAN_SOURCE_DIR "/hw/sim/bodies/male_average.ply");
  auto poser = BodyPoser::shipped();
  ASSERT_TRUE(rest.ok() && poser.ok());
  auto posed = (*poser)->pose(*rest, desc->simulation.posture);
  ASSERT_TRUE(posed.ok()) << posed.status().message();
  // The scene's subject is the posed body, turned by 30 degrees about the vertical
  // (the face from +Z toward +X) and moved: vertex for vertex, up to where it stands.
  const TriangleMesh& subject = (*rig)->scene().subject();
  ASSERT_EQ(subject.vertices.size(), posed->mesh.vertices.size());
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(30 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d shift = subject.vertices[0].cast<double>() - turn * posed->mesh.vertices[0].cast<double>();
  for (size_t i = 0; i < subject.vertices.size(); i += 101)
    EXPECT_LT((subject.vertices[i].cast<double>() - turn * posed->mesh.vertices[i].cast<double>() - shift).norm(),
              0.01);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Vec3f& v : subject.vertices) mean += v.cast<double>();
  mean /= static_cast<double>(subject.vertices.size());
  EXPECT_NEAR(mean.x(), 120, 0.01);
  EXPECT_NEAR(mean.z(), -80, 0.01);
  // A mesh that is not a MakeHuman body cannot be posed: a clear error.
  auto bunny = read_ply_mesh(BODYSCAN_SOURCE_DIR "/tests/data/bunny.ply");
  ASSERT_TRUE(bunny.ok());
  auto refused = SimulatedRig::create(*desc, *bunny);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("posing the simulated subject"), std::string::npos);
}

TEST(SimulatedRig, ShippedRigsTakeAStandingAdultOfTwoMetres) {
  // The demo body scaled to 2.0 m (arms abducted as shipped): it stands inside both
  // shipped frames, clear of the tubing, and every camera sees all of it.
  auto body = read_ply_mesh(BODYSCAN_SOURCE_DIR "/hw/sim/bodies/male_average.ply");
  ASSERT_TRUE(body.ok());
  float lo = 1e9f, hi = -1e9f;
  for (const Vec3f& v : body->vertices) lo = std::min(lo, v.y()), hi = std::max(hi, v.y());
  for (Vec3f& v : body->vertices) v *= 2000.f / (hi - lo);
  for (const std::string& name : shipped_rig_names()) {
    auto desc = load_rig_description(*shipped_rig_path(name));
    ASSERT_TRUE(desc.ok());
    auto rig = SimulatedRig::create(*desc, *body);
    ASSERT_TRUE(rig.ok()) << rig.status().message();
    const FrameGeometry& f = desc->frame;
    for (const Vec3f& v : (*rig)->scene().subject().vertices) {
      ASSERT_LT(std::abs(v.x()), 0.5 * f.width - 2 * f.tube) << name;
      ASSERT_LT(std::abs(v.z()), 0.5 * f.depth - 2 * f.tube) << name;  // the scan volume (recon/scan/triangulate.hpp)
      ASSERT_LT(v.y(), f.top_height - f.tube) << name;
    }
    for (size_t c = 0; c < (*rig)->num_cameras(); ++c) {
      const CameraModel& m = (*rig)->renderer(c).model();
      for (const Vec3f& v : (*rig)->scene().subject().vertices) {
        const auto p = m.project(v.cast<double>());
        ASSERT_TRUE(p && m.in_image(*p)) << name << " camera " << c;
      }
      // The body hides none of the eight frame lights the camera needs; the light
      // faces sit tube/2 from the pole's centre line.
      for (const Vec3d& light : visible_lights(f, desc->cameras[c].position.z() > 0)) {
        const Vec3d to = light - m.centre();
        EXPECT_FALSE((*rig)->scene().occluded(m.centre(), to.normalized(), to.norm() - 1.0))
            << name << " camera " << desc->cameras[c].id << " light " << light.transpose();
      }
    }
  }
}

// The thesis rig with one small camera, its subject moving as `motion` says.
StatusOr<std::unique_ptr<SimulatedRig>> small_thesis_rig(const SubjectMotion& motion) {
  ASSIGN_OR_RETURN(const std::string path, shipped_rig_path("thesis"));
  ASSIGN_OR_RETURN(RigDescription desc, load_rig_description(path));
  desc.simulation.motion = motion;
  desc.cameras.resize(1);
  desc.cameras[0].width = 64;
  desc.cameras[0].height = 64;
  return SimulatedRig::create(desc);
}

TEST(SimulatedRig, SubjectStandsOnTheFloorAndBreathes) {
  auto rig = small_thesis_rig({.breathing_mm = 6, .breathing_hz = 0.5});
  ASSERT_TRUE(rig.ok()) << rig.status().message();
  const Scene& s = (*rig)->scene();
  float min_y = 1e9f;
  for (const Vec3f& v : s.subject().vertices) min_y = std::min(min_y, v.y());
  EXPECT_NEAR(min_y, s.floor_y(), 1e-3);
  // At half a breathing period the chest has moved out by the full amplitude.
  const TriangleMesh rest = s.subject();
  const_cast<Scene&>(s).set_time(1.0);
  double most = 0;
  for (size_t i = 0; i < rest.vertices.size(); ++i)
    most = std::max(most, static_cast<double>((s.subject().vertices[i] - rest.vertices[i]).norm()));
  EXPECT_NEAR(most, 6.0, 0.01);
}

// The scene poses a swaying subject by subject_sway(), the function benchmarks hold
// a scan's estimated sway against: every vertex moves by it, and it is what the
// description asks (sideways by sway_mm, front to back by half, at sway_hz).
TEST(SimulatedRig, ASwayingSubjectMovesBySubjectSway) {
  const SubjectMotion motion{.sway_mm = 3, .sway_hz = 0.25};
  auto rig = small_thesis_rig(motion);
  ASSERT_TRUE(rig.ok()) << rig.status().message();
  Scene& s = const_cast<Scene&>((*rig)->scene());
  s.set_time(0.5);  // away from rest
  const TriangleMesh rest = s.subject();
  const Vec3d at_rest = subject_sway(motion, 0.5);
  for (double t : {1.0, 2.0, 3.7}) {
    s.set_time(t);
    const Vec3d moved = subject_sway(motion, t) - at_rest;
    double worst = 0;
    for (size_t i = 0; i < rest.vertices.size(); i += 97)
      worst = std::max(worst, ((s.subject().vertices[i] - rest.vertices[i]).cast<double>() - moved).norm());
    EXPECT_LT(worst, 1e-3) << "at " << t << " s";
  }
  // One second is a quarter period: sideways from 0 to the full 3 mm.
  EXPECT_NEAR(subject_sway(motion, 1.0).x(), 3.0, 1e-9);
  EXPECT_NEAR(subject_sway(motion, 0.0).x(), 0.0, 1e-9);
  EXPECT_NEAR(subject_sway(motion, 1.0).z(), 1.5 * std::sin(M_PI / 2 + 1.3), 1e-9);
  EXPECT_EQ(subject_sway(motion, 1.0).y(), 0.0);
}

}  // namespace
}  // namespace bodyscan::hw::sim
