#include "hw/rig_description.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

namespace bodyscan::hw {
namespace {

RigDescription load_shipped(const std::string& name) {
  auto path = shipped_rig_path(name);
  EXPECT_TRUE(path.ok()) << path.status().message();
  auto rig = load_rig_description(*path);
  EXPECT_TRUE(rig.ok()) << rig.status().message();
  return rig.ok() ? *rig : RigDescription{};
}

// The shipped thesis layout as JSON, for tests to break.
nlohmann::json thesis_json() { return nlohmann::json::parse(to_json(load_shipped("thesis"))); }

std::string parse_error(const nlohmann::json& j) {
  auto r = parse_rig_description(j.dump(), "test.json");
  EXPECT_FALSE(r.ok());
  return r.ok() ? "" : r.status().message();
}

TEST(RigDescription, ShippedLayoutsLoad) {
  const RigDescription thesis = load_shipped("thesis");
  EXPECT_EQ(thesis.cameras.size(), 3u);
  EXPECT_EQ(thesis.lasers.size(), 4u);
  // One laser at a time: sweeps that reach across the whole body make any two lasers'
  // planes cross inside the frame at some pair of steps (docs/scan-processing.md).
  ASSERT_EQ(thesis.laser_groups.size(), 4u);
  EXPECT_EQ(thesis.laser_groups[0].size(), 1u);
  EXPECT_TRUE(std::filesystem::exists(thesis.simulation.subject)) << thesis.simulation.subject;
  const RigDescription square = load_shipped("square");
  EXPECT_EQ(square.cameras.size(), 4u);
  EXPECT_EQ(square.frame.width, square.frame.depth);
  // The tiered layout: the square's columns with a low and a high tier, each camera
  // looking at the middle of the frame's lights from its height, one laser at a time.
  const RigDescription tiered = load_shipped("tiered");
  ASSERT_EQ(tiered.cameras.size(), 8u);
  ASSERT_EQ(tiered.lasers.size(), 8u);
  EXPECT_EQ(tiered.laser_groups.size(), 8u);
  for (const CameraDescription& c : tiered.cameras) {
    EXPECT_TRUE(c.position.y() < 600 || c.position.y() > 1700) << c.id;
    EXPECT_NE(c.id.find(c.position.y() < 600 ? "-low" : "-high"), std::string::npos) << c.id;
  }
  EXPECT_EQ(tiered.frame.width, square.frame.width);
  EXPECT_EQ(tiered.processing.max_view_deg, 90.0);  // no view cut (docs/rig-description.md)
  EXPECT_EQ(square.processing.max_view_deg, 90.0);
  EXPECT_FALSE(shipped_rig_path("hexagon").ok());
}

TEST(RigDescription, EveryShippedCameraSeesTheEightLightsOfItsSide) {
  for (const std::string& name : shipped_rig_names()) {
    const RigDescription rig = load_shipped(name);
    for (const CameraDescription& c : rig.cameras) {
      const std::vector<Vec3d> lights = visible_lights(rig.frame, c.position.z() > 0);
      ASSERT_EQ(lights.size(), 8u);
      const CameraModel m = c.model();
      for (const Vec3d& l : lights) {
        const auto p = m.project(l);
        ASSERT_TRUE(p) << name << " " << c.id;
        EXPECT_GT(p->x(), 20) << name << " " << c.id << " light " << l.transpose();
        EXPECT_LT(p->x(), c.width - 21) << name << " " << c.id << " light " << l.transpose();
        EXPECT_GT(p->y(), 20) << name << " " << c.id << " light " << l.transpose();
        EXPECT_LT(p->y(), c.height - 21) << name << " " << c.id << " light " << l.transpose();
      }
    }
  }
}

TEST(RigDescription, EveryShippedLaserSweepCrossesThePolesOverMostOfItsSteps) {
  // Calibration fits each laser's sweep to the frames whose plane crosses the front
  // and back poles inside the frame; the rest of the sweep takes its planes from the
  // fit (the square rig's side lasers cross both poles on 47 % of their steps; the fit
  // extrapolates within 0.3 mm, tests/recon/scan/laser_sweep_test.cpp). The middle
  // and at least 40 % of the steps must cross.
  for (const std::string& name : shipped_rig_names()) {
    const RigDescription rig = load_shipped(name);
    const double half_w = 0.5 * rig.frame.width - rig.frame.tube, half_d = 0.5 * rig.frame.depth;
    for (const LaserDescription& l : rig.lasers) {
      int crossing = 0;
      for (int step = l.min_step; step <= l.max_step; ++step) {
        const Vec3d n = l.plane_normal(step);
        EXPECT_NEAR(n.dot(l.axis), 0.0, 1e-12);
        bool both = true;
        for (double z : {-half_d, half_d}) {
          // x where the plane meets the pole z = const (any height: the plane is vertical).
          const double x = (l.plane_offset(step) - n.z() * z) / n.x();
          both = both && std::abs(x) < half_w;
          if (step == 0) {
            EXPECT_LT(std::abs(x), half_w) << name << " " << l.id << " pole z " << z;
          }
        }
        crossing += both;
      }
      EXPECT_GT(crossing, 0.4 * (l.max_step - l.min_step + 1)) << name << " " << l.id;
    }
  }
}

TEST(RigDescription, PlaneTurnsByTheStepAngle) {
  LaserDescription l;
  l.position = Vec3d(0, 1000, 2000);
  l.aim = -Vec3d::UnitZ();
  l.step_angle_deg = 0.1;
  EXPECT_NEAR((l.plane_normal(0) - Vec3d::UnitY().cross(-Vec3d::UnitZ())).norm(), 0.0, 1e-12);
  const double angle = std::acos(std::clamp(l.plane_normal(0).dot(l.plane_normal(100)), -1.0, 1.0));
  EXPECT_NEAR(angle * 180 / M_PI, 10.0, 1e-9);
  EXPECT_NEAR(l.plane_offset(7), l.plane_normal(7).dot(l.position), 1e-9);
}

TEST(RigDescription, RoundTripsThroughJson) {
  const RigDescription a = load_shipped("thesis");
  auto b = parse_rig_description(to_json(a), a.source);
  ASSERT_TRUE(b.ok()) << b.status().message();
  EXPECT_EQ(to_json(*b), to_json(a));
  EXPECT_EQ(b->cameras[1].distortion.p2, a.cameras[1].distortion.p2);
  EXPECT_EQ(b->simulation.subject, a.simulation.subject);
  EXPECT_EQ(b->processing.max_view_deg, 90.0);  // no cut unless the layout asks
  auto j = thesis_json();
  j["processing"]["max_view_deg"] = 75;
  auto c = parse_rig_description(j.dump(), a.source);
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_EQ(c->processing.max_view_deg, 75.0);
  EXPECT_EQ(nlohmann::json::parse(to_json(*c))["processing"]["max_view_deg"], 75.0);
}

TEST(RigDescription, TheSubjectsPostureIsReadCheckedAndWrittenBack) {
  auto j = thesis_json();
  j["simulation"]["posture"] = {{"arm_abduction_deg", 20}, {"ankle_distance_mm", 250}};
  auto r = parse_rig_description(j.dump(), "test.json");
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->simulation.posture.arm_abduction_deg[0], 20.0);
  EXPECT_EQ(r->simulation.posture.arm_abduction_deg[1], 20.0);
  EXPECT_EQ(r->simulation.posture.ankle_distance_mm, 250.0);
  j["simulation"]["posture"] = {{"arm_abduction_deg", {nullptr, 30}}};
  r = parse_rig_description(j.dump(), "test.json");
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_FALSE(r->simulation.posture.arm_abduction_deg[0]);
  EXPECT_EQ(r->simulation.posture.arm_abduction_deg[1], 30.0);
  auto again = parse_rig_description(to_json(*r), "again");
  ASSERT_TRUE(again.ok()) << again.status().message();
  EXPECT_EQ(to_json(*again), to_json(*r));
  EXPECT_FALSE(load_shipped("thesis").simulation.posture.any());
  j["simulation"]["posture"] = {{"arm_abduction_deg", 95}};
  EXPECT_NE(parse_error(j).find("rig.simulation.posture: 'arm_abduction_deg' must be 0-80"), std::string::npos)
      << parse_error(j);
  j["simulation"]["posture"] = {{"arm_abduction_deg", {10, 20, 30}}};
  EXPECT_NE(parse_error(j).find("[left, right]"), std::string::npos) << parse_error(j);
  j["simulation"]["posture"] = {{"ankle_distance_mm", 50}};
  EXPECT_NE(parse_error(j).find("'ankle_distance_mm' must be 100-700"), std::string::npos) << parse_error(j);
  j["simulation"]["posture"] = {{"knees", 5}};
  EXPECT_NE(parse_error(j).find("unknown field 'knees'"), std::string::npos) << parse_error(j);
}

TEST(RigDescription, ErrorsNameTheField) {
  EXPECT_NE(parse_error(nlohmann::json::parse("{}")).find("missing field 'frame'"), std::string::npos);
  {
    auto r = parse_rig_description("{\"frame\": [1,", "broken.json");
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.status().message().find("broken.json: not valid JSON"), std::string::npos) << r.status().message();
  }
  {
    // A description nested past any real one's depth is refused as it is read.
    auto r =
        parse_rig_description("{\"frame\": " + std::string(300000, '[') + std::string(300000, ']') + "}", "deep.json");
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.status().message().find("deep.json: not valid JSON, or nested more than 64"), std::string::npos)
        << r.status().message();
  }
  auto j = thesis_json();
  j["cameras"][1]["focal_mm"] = -4;
  EXPECT_NE(parse_error(j).find("rig.cameras[1]: 'focal_mm' must be positive"), std::string::npos) << parse_error(j);
  j = thesis_json();
  j["cameras"][0]["focl_mm"] = 4;
  EXPECT_NE(parse_error(j).find("unknown field 'focl_mm'"), std::string::npos);
  j = thesis_json();
  j["cameras"][2]["id"] = j["cameras"][0]["id"];
  EXPECT_NE(parse_error(j).find("is used twice"), std::string::npos);
  j = thesis_json();
  j["lasers"][0]["position"] = {1, 2};
  EXPECT_NE(parse_error(j).find("rig.lasers[0]: 'position' must be [x, y, z]"), std::string::npos) << parse_error(j);
  j = thesis_json();
  j["laser_groups"][0][0] = "nope";
  EXPECT_NE(parse_error(j).find("unknown laser id \"nope\""), std::string::npos);
  j = thesis_json();
  j["frame"]["light_x"] = {0, 1, 2};
  EXPECT_NE(parse_error(j).find("2 distinct positions"), std::string::npos);
  j = thesis_json();
  j["cameras"][0]["distortion"]["k1"] = -3.0;
  EXPECT_NE(parse_error(j).find("folds over"), std::string::npos) << parse_error(j);
  j = thesis_json();
  j["processing"]["max_view_deg"] = 120;
  EXPECT_NE(parse_error(j).find("rig.processing: max_view_deg must be at most 90"), std::string::npos)
      << parse_error(j);
  j = thesis_json();
  j["processing"]["smoothing"] = 3;
  EXPECT_NE(parse_error(j).find("unknown field 'smoothing'"), std::string::npos) << parse_error(j);
  EXPECT_FALSE(load_rig_description("/nonexistent/rig.json").ok());
}

TEST(RigDescription, LasersWhosePlanesCrossInsideTheFrameCannotRunTogether) {
  // The two front lasers sweep the same region: their planes meet inside the frame.
  auto j = thesis_json();
  using nlohmann::json;  // json::array: a braced list of string pairs would become an object
  j["laser_groups"] =
      json::array({json::array({"front-left", "front-right"}), json::array({"back-left", "back-right"})});
  const std::string e = parse_error(j);
  EXPECT_NE(e.find("cannot run together: their planes cross inside the frame"), std::string::npos) << e;
  // Lasers far apart may run together; a laser left out of every group runs alone.
  j = thesis_json();
  j["lasers"][0]["aim"] = json::array({0, 0, -1});
  j["lasers"][0]["min_step"] = -20;
  j["lasers"][0]["max_step"] = 20;
  j["lasers"][3]["aim"] = json::array({0, 0, 1});
  j["lasers"][3]["min_step"] = -20;
  j["lasers"][3]["max_step"] = 20;
  j["laser_groups"] = json::array({json::array({"front-left", "back-right"})});
  auto r = parse_rig_description(j.dump(), "test.json");
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->laser_groups.size(), 3u) << e;
}

TEST(RigDescription, RealDevicesExampleLoadsAndRoundTrips) {
  const std::string path = std::string(BODYSCAN_SOURCE_DIR) + "/hw/rigs/examples/shop-example.json";
  auto rig = load_rig_description(path);
  ASSERT_TRUE(rig.ok()) << rig.status().message();
  EXPECT_TRUE(rig->has_real_devices());
  EXPECT_EQ(rig->cameras[0].device.backend, "aravis");
  EXPECT_EQ(rig->cameras[0].device.packet_size, 8192);
  EXPECT_EQ(rig->controller.backend, "tmcl");
  EXPECT_EQ(rig->controller.usb_vendor, 0x2a3c);
  ASSERT_EQ(rig->controller.lasers.size(), 4u);
  EXPECT_EQ(rig->controller.lasers[2].output, 2);
  EXPECT_EQ(rig->controller.lasers[2].microsteps_per_step, 16);
  auto again = parse_rig_description(to_json(*rig), "again");
  ASSERT_TRUE(again.ok()) << again.status().message();
  EXPECT_EQ(to_json(*again), to_json(*rig));
  EXPECT_FALSE(load_shipped("thesis").has_real_devices());
}

TEST(RigDescription, ControllerWiringMistakesAreNamed) {
  nlohmann::json j = thesis_json();
  j["controller"] = {{"backend", "tmcl"}, {"lasers", {{"front-left", {{"output", 0}, {"axis", 0}}}}}};
  EXPECT_NE(parse_error(j).find("laser 'front-right' is not wired"), std::string::npos) << parse_error(j);
  j["controller"]["lasers"] = {{"front-left", {{"output", 0}, {"axis", 0}}},
                               {"front-right", {{"output", 0}, {"axis", 1}}},
                               {"back-left", {{"output", 2}, {"axis", 2}}},
                               {"back-right", {{"output", 3}, {"axis", 3}}}};
  EXPECT_NE(parse_error(j).find("output 0 is wired twice"), std::string::npos) << parse_error(j);
  j["controller"]["lasers"]["front-right"]["output"] = 1;
  j["controller"]["lasers"]["back-right"]["axis"] = 0;
  EXPECT_NE(parse_error(j).find("axis 0 turns two lasers"), std::string::npos) << parse_error(j);
  j["controller"]["lasers"]["back-right"]["axis"] = 3;
  j["controller"]["watchdog_ms"] = 0;
  EXPECT_NE(parse_error(j).find("watchdog_ms 0 (none) is refused for a board that switches lasers"), std::string::npos)
      << parse_error(j);
  j["controller"]["watchdog_ms"] = 500;
  j["controller"]["usb"] = {{"vendor", "xyz"}};
  EXPECT_NE(parse_error(j).find("4 hex digits"), std::string::npos) << parse_error(j);
  j["controller"].erase("usb");
  j["controller"]["backend"] = "simstep";
  EXPECT_NE(parse_error(j).find("'sim' or 'tmcl'"), std::string::npos);
  j = thesis_json();
  j["cameras"][0]["device"] = {{"backend", "aravis"}};
  EXPECT_NE(parse_error(j).find("needs its 'id'"), std::string::npos) << parse_error(j);
}

}  // namespace
}  // namespace bodyscan::hw
