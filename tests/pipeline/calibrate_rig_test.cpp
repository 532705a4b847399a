// Calibration of the simulated rig from what its cameras see, against the
// simulator's ground truth, and its errors when the rig is broken.
#include <gtest/gtest.h>

#include <cstdio>

#include "hw/device_rig.hpp"
#include "hw/sim/sim_rig.hpp"
#include "pipeline/calibrate.hpp"
#include "pipeline/rig_backend.hpp"
#include "tests/half_resolution.hpp"

namespace bodyscan::pipeline {
namespace {

using testing::half_resolution_rig;
hw::RigDescription half_resolution() { return half_resolution_rig(); }

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
    EXPECT_LT((cc.centre - truth.centre()).norm(), 15.0)
        << cc.camera_id;                               // mm, 3 m off, half-size pixels; full size: < 4
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

// Before a real camera a person holds the dot grid: asked for each camera in turn,
// asked again with the reason when the picture cannot be used (here: the board
// held out of view the first time before camera 1), and asked to clear the rig
// after the last. Training mode asks for the simulated cameras the same way.
TEST(CalibrateRig, APersonHoldingTheDotGridIsAskedAgainWhenThePictureIsUnusable) {
  const hw::RigDescription desc = half_resolution();
  auto devices = hw::DeviceRig::open(desc);
  ASSERT_TRUE(devices.ok()) << devices.status().message();
  std::vector<OperatorRequest> asked;
  Rig rig = rig_handle(
      **devices,
      [&](const OperatorRequest& r) {
        asked.push_back(r);
        return Status::Ok();
      },
      true);
  ASSERT_TRUE(rig.person_holds_dot_grid);
  for (size_t c = 0; c < desc.cameras.size(); ++c) EXPECT_TRUE(rig.person_holds_dot_grid(c));
  bool fumbled = false;
  auto hold = rig.hold_dot_grid;
  rig.hold_dot_grid = [&](size_t c, bool held, const std::string& why) {
    Status st = hold(c, held, why);
    if (c == 1 && held && !fumbled) {  // said "holding it", but out of the camera's view
      fumbled = true;
      (*devices)->simulation()->hold_dot_grid(c, false);
    }
    return st;
  };
  auto cal = calibrate_rig(rig);
  ASSERT_TRUE(cal.ok()) << cal.status().message();
  expect_matches_truth(desc, *cal);
  ASSERT_EQ(asked.size(), desc.cameras.size() + 2);
  const std::vector<size_t> cameras = {0, 1, 1, 2};
  for (size_t i = 0; i < cameras.size(); ++i) {
    EXPECT_EQ(asked[i].kind, OperatorRequest::Kind::kHoldDotGrid) << i;
    EXPECT_EQ(asked[i].camera, cameras[i]) << i;
    EXPECT_EQ(asked[i].camera_id, desc.cameras[cameras[i]].id) << i;
    EXPECT_NE(asked[i].text().find(desc.cameras[cameras[i]].id), std::string::npos) << asked[i].text();
  }
  EXPECT_TRUE(asked[0].why.empty());
  EXPECT_TRUE(asked[1].why.empty());
  EXPECT_NE(asked[2].why.find("camera '" + desc.cameras[1].id + "'"), std::string::npos) << asked[2].why;
  EXPECT_NE(asked[2].why.find("dots"), std::string::npos) << asked[2].why;
  EXPECT_TRUE(asked[3].why.empty());
  std::printf("asked again before camera %s: %s\n", asked[2].camera_id.c_str(), asked[2].why.c_str());
  EXPECT_EQ(asked.back().kind, OperatorRequest::Kind::kRemoveDotGrid);
  for (int i = 0; i < (*devices)->controller().num_lasers(); ++i) EXPECT_FALSE((*devices)->controller().laser_on(i));
}

// Nobody to hold the board (the operator cancels, standard input closes): the
// calibration stops with that, every laser off, no board left before a camera.
TEST(CalibrateRig, NobodyToHoldTheDotGridStopsTheCalibration) {
  const hw::RigDescription desc = half_resolution();
  auto devices = hw::DeviceRig::open(desc);
  ASSERT_TRUE(devices.ok()) << devices.status().message();
  int asked = 0;
  const Rig rig = rig_handle(
      **devices,
      [&](const OperatorRequest& r) {
        return ++asked == 2 ? cancelled("nobody answered about camera '" + r.camera_id + "'") : Status::Ok();
      },
      true);
  auto cal = calibrate_rig(rig);
  ASSERT_FALSE(cal.ok());
  EXPECT_EQ(cal.status().code(), StatusCode::kCancelled);
  EXPECT_NE(cal.status().message().find(desc.cameras[1].id), std::string::npos) << cal.status().message();
  EXPECT_EQ(asked, 2);
  for (int i = 0; i < (*devices)->controller().num_lasers(); ++i) EXPECT_FALSE((*devices)->controller().laser_on(i));
}

// A simulated board is placed exactly: its unusable picture is an error at once,
// nobody is asked again.
TEST(CalibrateRig, ASimulatedBoardIsNotRetried) {
  hw::RigDescription desc = half_resolution();
  desc.cameras[0].exposure_us = 1;
  auto devices = hw::DeviceRig::open(desc);
  ASSERT_TRUE(devices.ok()) << devices.status().message();
  int asked = 0;
  const Rig rig = rig_handle(**devices, [&](const OperatorRequest&) { return ++asked, Status::Ok(); });
  EXPECT_FALSE(rig.person_holds_dot_grid(0));
  auto cal = calibrate_rig(rig);
  ASSERT_FALSE(cal.ok());
  EXPECT_EQ(cal.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(cal.status().message().find("black"), std::string::npos) << cal.status().message();
  EXPECT_EQ(asked, 0);
}

}  // namespace
}  // namespace bodyscan::pipeline
