// Calibration of the simulated rig from what its cameras see, against the
// simulator's ground truth, and its errors when the rig is broken.
#include <gtest/gtest.h>

#include "hw/sim/sim_rig.hpp"
#include "server/pipeline/calibrate.hpp"
#include "server/pipeline/rig_backend.hpp"

namespace bodyscan::pipeline {
namespace {

// The shipped thesis rig at half resolution (the same lenses on pixels twice the
// size), so that a calibration renders in a few seconds.
hw::RigDescription half_resolution(const std::string& name = "thesis") {
  auto desc = hw::load_rig_description(*hw::shipped_rig_path(name));
  EXPECT_TRUE(desc.ok()) << desc.status().message();
  for (hw::CameraDescription& c : desc->cameras) {
    c.width /= 2;
    c.height /= 2;
    c.pixel_size_um *= 2;
    c.blur_px /= 2;
  }
  return *desc;
}

std::unique_ptr<hw::sim::SimulatedRig> make(const hw::RigDescription& desc) {
  auto rig = hw::sim::SimulatedRig::create(desc);
  EXPECT_TRUE(rig.ok()) << rig.status().message();
  return rig.ok() ? std::move(rig).value() : nullptr;
}

void expect_matches_truth(const hw::RigDescription& desc, const RigCalibration& cal) {
  ASSERT_EQ(cal.cameras.size(), desc.cameras.size());
  for (size_t c = 0; c < desc.cameras.size(); ++c) {
    const CameraCalibration& cc = cal.cameras[c];
    const hw::CameraModel truth = desc.cameras[c].model();
    EXPECT_EQ(cc.side, truth.centre().z() > 0 ? FrameSide::kFront : FrameSide::kBack) << cc.camera_id;
    // The centre of projection comes out of the two frames' transforms alone.
    EXPECT_LT((cc.centre - truth.centre()).norm(), 15.0) << cc.camera_id;  // mm, 3 m off, half-size pixels; full size: < 4
    EXPECT_LT(cc.ray_spread_mm, 4.0) << cc.camera_id;  // half-size pixels; full size: under 1 mm
    EXPECT_LT(cc.lens.held_out_rms_px(), 0.05) << cc.camera_id;
    // Each camera sees the lasers on its own side of the frame on the poles.
    for (int l : cal.lasers_seen[c]) {
      EXPECT_EQ(desc.lasers[static_cast<size_t>(l)].position.z() > 0, truth.centre().z() > 0) << cc.camera_id;
    }
    EXPECT_FALSE(cal.lasers_seen[c].empty()) << cc.camera_id;
  }
  // Every laser's plane at the ends of its sweep, against the truth where the body stands.
  for (const LaserSighting& s : cal.sightings) {
    const hw::LaserDescription& l = desc.lasers[static_cast<size_t>(s.laser)];
    const Eigen::Vector3d centre(0, 1000, 0);
    const Eigen::Vector3d on = centre - (s.plane.normal.dot(centre) - s.plane.offset) * s.plane.normal;
    EXPECT_LT(std::abs(l.plane_normal(s.step).dot(on) - l.plane_offset(s.step)), 3.0) << l.id << " step " << s.step;
  }
}

TEST(CalibrateRig, FindsEveryCameraAndLaserOnTheThesisRig) {
  const hw::RigDescription desc = half_resolution();
  auto rig = make(desc);
  ASSERT_TRUE(rig);
  auto cal = calibrate_rig(rig_handle(*rig));
  ASSERT_TRUE(cal.ok()) << cal.status().message();
  expect_matches_truth(desc, *cal);
  for (int i = 0; i < rig->controller().num_lasers(); ++i) EXPECT_FALSE(rig->controller().laser_on(i));
}

TEST(CalibrateRig, CamerasMovedAndTurnedStillCalibrate) {
  hw::RigDescription desc = half_resolution();
  // Nothing re-tuned: the cameras stand elsewhere, look elsewhere, one has another lens.
  desc.cameras[0].position += Eigen::Vector3d(-150, 30, 250);
  desc.cameras[0].look_at += Eigen::Vector3d(30, -20, 0);
  desc.cameras[1].position += Eigen::Vector3d(200, 40, 200);
  desc.cameras[1].focal_mm = 4.5;
  desc.cameras[2].position += Eigen::Vector3d(300, 0, -100);
  desc.cameras[2].look_at += Eigen::Vector3d(-50, 0, 0);
  auto rig = make(desc);
  ASSERT_TRUE(rig);
  auto cal = calibrate_rig(rig_handle(*rig));
  ASSERT_TRUE(cal.ok()) << cal.status().message();
  expect_matches_truth(desc, *cal);
}

TEST(CalibrateRig, AFrameLightThatStaysOffIsAClearError) {
  const hw::RigDescription desc = half_resolution();
  auto rig = make(desc);
  ASSERT_TRUE(rig);
  rig->break_frame_light(hw::visible_lights(desc.frame, true)[5]);  // seen by the front cameras
  auto cal = calibrate_rig(rig_handle(*rig));
  ASSERT_FALSE(cal.ok());
  EXPECT_NE(cal.status().message().find("found 7 frame lights"), std::string::npos) << cal.status().message();
  EXPECT_NE(cal.status().message().find("front-"), std::string::npos) << "names the camera: " << cal.status().message();
}

TEST(CalibrateRig, ALaserAimedPastTheFrameIsAClearError) {
  hw::RigDescription desc = half_resolution();
  desc.lasers[1].aim = Eigen::Vector3d(1, 0, 0);  // along the front, never across the frame
  auto rig = make(desc);
  ASSERT_TRUE(rig);
  auto cal = calibrate_rig(rig_handle(*rig));
  ASSERT_FALSE(cal.ok());
  EXPECT_NE(cal.status().message().find("laser '" + desc.lasers[1].id + "'"), std::string::npos)
      << cal.status().message();
  EXPECT_NE(cal.status().message().find("poles"), std::string::npos) << cal.status().message();
  for (int i = 0; i < rig->controller().num_lasers(); ++i) EXPECT_FALSE(rig->controller().laser_on(i));
}

TEST(CalibrateRig, ABlackCameraIsAClearError) {
  hw::RigDescription desc = half_resolution();
  desc.cameras[2].exposure_us = 1;  // the lens cap on: black frames
  auto rig = make(desc);
  ASSERT_TRUE(rig);
  auto cal = calibrate_rig(rig_handle(*rig));
  ASSERT_FALSE(cal.ok());
  EXPECT_NE(cal.status().message().find("camera '" + desc.cameras[2].id + "'"), std::string::npos)
      << cal.status().message();
  EXPECT_NE(cal.status().message().find("black"), std::string::npos) << cal.status().message();
}

}  // namespace
}  // namespace bodyscan::pipeline
