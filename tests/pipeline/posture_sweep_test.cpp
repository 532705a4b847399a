// The posture check before a scan, on the simulated thesis rig with its demo body
// posed by skinning: the quick sweep reads the posture the full automatic set reads
// on the posed true mesh, and flags what lies outside the scanning posture.
#include <gtest/gtest.h>

#include "hw/sim/sim_rig.hpp"
#include "pipeline/posture_sweep.hpp"
#include "pipeline/rig_backend.hpp"
#include "recon/measure/body_measurements.hpp"

namespace bodyscan::pipeline {
namespace {

struct Posed {
  std::unique_ptr<hw::sim::SimulatedRig> rig;
  BodyMeasurements truth;  // the automatic set on the posed true mesh
};

Posed posed_rig(double arms, double feet, double turn, Eigen::Vector2d at) {
  SimulatedSubject s;
  s.posture.arm_abduction_deg = {arms, arms};
  s.posture.ankle_distance_mm = feet;
  s.turn_deg = turn;
  s.position_mm = at;
  auto rig = open_simulated_rig("thesis", s);
  EXPECT_TRUE(rig.ok()) << rig.status().message();
  Posed out;
  if (!rig.ok()) return out;
  out.rig = std::move(rig).value();
  BodyMeasureOptions mo;
  mo.floor_y = -0.5 * out.rig->description().frame.tube;
  StatusOr<BodyMeasurements> truth = measure_body(out.rig->scene().subject(), mo);
  EXPECT_TRUE(truth.ok()) << truth.status().message();
  if (truth.ok()) out.truth = std::move(*truth);
  return out;
}

class PostureSweepTest : public ::testing::Test {
 protected:
  // The rig's calibration does not depend on who stands in it: made once.
  static const RigCalibration& calibration(const Rig& rig) {
    static const StatusOr<RigCalibration> cal = calibrate_rig(rig);
    EXPECT_TRUE(cal.ok()) << cal.status().message();
    return *cal;
  }

  static const PostureCheck* check(const PostureSweep& s, const std::string& part) {
    for (const PostureCheck& c : s.checks)
      if (c.part == part) return &c;
    return nullptr;
  }
};

// Turned 20 degrees and standing off the rig's centre, in the scanning posture:
// the sweep reads each part within a few degrees or mm of the truth's reading and
// passes every check. Tolerances: 3 deg for an arm (its axis from a coarser
// surface), 15 mm for the ankles, 1 deg for the turn.
TEST_F(PostureSweepTest, ReadsTheScanningPostureOfATurnedBodyAsTheTruthDoes) {
  Posed p = posed_rig(42, 380, 20, {150, -100});
  ASSERT_TRUE(p.rig);
  const Rig rig = rig_handle(*p.rig);
  StatusOr<PostureSweep> sweep = sweep_posture(rig, calibration(rig));
  ASSERT_TRUE(sweep.ok()) << sweep.status().message();
  const BodyPosture &read = sweep->posture, &truth = p.truth.posture;
  for (int side = 0; side < 2; ++side) {
    ASSERT_TRUE(read.arm_abduction_deg[side] && truth.arm_abduction_deg[side]) << "arm " << side;
    EXPECT_NEAR(*read.arm_abduction_deg[side], *truth.arm_abduction_deg[side], 3.0) << "arm " << side;
  }
  ASSERT_TRUE(read.ankle_distance_mm && truth.ankle_distance_mm);
  EXPECT_NEAR(*read.ankle_distance_mm, *truth.ankle_distance_mm, 15.0);
  EXPECT_NEAR(read.turn_deg, truth.turn_deg, 1.0);
  EXPECT_NEAR(read.position_x_mm, truth.position_x_mm, 10.0);
  EXPECT_NEAR(read.position_z_mm, truth.position_z_mm, 10.0);
  EXPECT_TRUE(sweep->ok);
  for (const char* part : {"arm_left", "arm_right", "feet", "turn"}) {
    const PostureCheck* c = check(*sweep, part);
    ASSERT_NE(c, nullptr) << part;
    EXPECT_TRUE(c->ok) << part << ": " << c->message;
  }
  EXPECT_EQ(check(*sweep, "head"), nullptr) << "the head is left to the full scan";
  EXPECT_FALSE(read.head_tilt_deg.has_value());
  // A quarter of the laser steps: 3 cameras, 4 lasers.
  EXPECT_GT(sweep->frames, 0u);
  EXPECT_GT(sweep->points, 1000u);
  for (size_t i = 0; i < p.rig->description().lasers.size(); ++i)
    EXPECT_FALSE(rig.controller->laser_on(static_cast<int>(i))) << "laser " << i;
  const nlohmann::json j = to_json(*sweep);
  EXPECT_TRUE(j["ok"].get<bool>());
  EXPECT_EQ(j["posture"]["checks"].size(), 4u);
}

// Arms brought down to 20 degrees and the ankles close together: both arms and
// the feet are flagged, with what to ask of the customer; the turn is not.
TEST_F(PostureSweepTest, FlagsArmsHeldLowAndFeetTogether) {
  Posed p = posed_rig(20, 200, 0, {0, 0});
  ASSERT_TRUE(p.rig);
  const Rig rig = rig_handle(*p.rig);
  StatusOr<PostureSweep> sweep = sweep_posture(rig, calibration(rig));
  ASSERT_TRUE(sweep.ok()) << sweep.status().message();
  EXPECT_FALSE(sweep->ok);
  for (const char* part : {"arm_left", "arm_right", "feet"}) {
    const PostureCheck* c = check(*sweep, part);
    ASSERT_NE(c, nullptr) << part;
    EXPECT_FALSE(c->ok) << part;
    EXPECT_FALSE(c->message.empty()) << part;
  }
  const PostureCheck* turn = check(*sweep, "turn");
  ASSERT_NE(turn, nullptr);
  EXPECT_TRUE(turn->ok) << turn->message;
  // Whatever the sweep read of the arms, the truth's reading agrees on the checks.
  for (const PostureCheck& t : p.truth.posture_checks) {
    if (const PostureCheck* c = check(*sweep, t.part)) {
      EXPECT_EQ(c->ok, t.ok) << t.part;
    }
  }
}

}  // namespace
}  // namespace bodyscan::pipeline
