// `bodyscan measure` as a user runs it.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "recon/geometry/sample_surface.hpp"
#include "recon/io/ply.hpp"
#include "tests/app/cli_runner.hpp"
#include "tests/shapes.hpp"
#include "tests/test_data.hpp"

namespace bodyscan {
namespace {

// A torso (radius 150) with an arm (radius 40) beside it, 600 mm tall.
TriangleMesh torso_and_arm() {
  return testing::merged(testing::prism(testing::circle(150), {0, 0}, 0, 600),
                         testing::prism(testing::circle(40, {230, 0}, 360), {230, 0}, 100, 600));
}

TEST(MeasureCli, GirthsOnAMeshAndAPointCloud) {
  const std::string dir = testing::temp_dir();
  const std::string mesh = dir + "/body.ply", points = dir + "/points.ply";
  ASSERT_TRUE(write_ply(mesh, torso_and_arm()).ok());
  ASSERT_TRUE(write_ply(points, sample_mesh_uniform(torso_and_arm(), 300000, 1, false)).ok());
  const double torso = 2 * 720 * 150 * std::sin(M_PI / 720), arm = 2 * 360 * 40 * std::sin(M_PI / 360);

  CliResult r = bodyscan("measure " + quote(mesh) + " --girth-y 310", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["kind"], "mesh");
  const nlohmann::json& m = j["measurements"][0];
  EXPECT_EQ(m["kind"], "girth");
  EXPECT_NEAR(m["value_mm"].get<double>(), torso, 1e-3);  // float vertices
  EXPECT_EQ(m["loops_cut"], 2);
  EXPECT_EQ(m["loop"].size(), 1440u);  // each quad's side and diagonal
  EXPECT_NEAR(m["loop"][0][1].get<double>(), 310, 1e-4);
  EXPECT_FALSE(m["algorithm"].get<std::string>().empty());
  EXPECT_EQ(m["name"], "girth at y 310");
  EXPECT_EQ(m["path"], m["tape"]);  // what the viewer draws, as the server's evaluation gives it
  EXPECT_EQ(m["closed"], true);

  r = bodyscan("measure " + quote(mesh) + " --girth-y 310 --near 230,310,40", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NEAR(nlohmann::json::parse(r.out)["measurements"][0]["value_mm"].get<double>(), arm, 1e-3);

  // A plane given directly (tilted 30 degrees about z) on the torso alone.
  r = bodyscan("measure " + quote(mesh) + " --plane 0,300,0,0.5,0.8660254,0 --near -150,300,0", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_GT(nlohmann::json::parse(r.out)["measurements"][0]["value_mm"].get<double>(), torso + 20);

  r = bodyscan("measure " + quote(points) + " --girth-y 300", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["kind"], "points");
  EXPECT_NEAR(j["measurements"][0]["value_mm"].get<double>(), torso, 2.0);

  r = bodyscan("measure " + quote(mesh) + " --girth-y 310 --arc 0,310,-150 --to -150,310,0", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(r.out)["measurements"][0];
  EXPECT_EQ(j["kind"], "arc");
  EXPECT_NEAR(j["value_mm"].get<double>(), torso / 4, 1e-3);
  EXPECT_NEAR(j["other_way_mm"].get<double>(), 3 * torso / 4, 1e-3);
  EXPECT_GE(j["path"].size(), 3u);
  r = bodyscan("measure " + quote(points) + " --girth-y 310 --arc 0,310,-150 --to -150,310,0", dir);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("needs a mesh"), std::string::npos) << r.err;

  r = bodyscan("measure --distance 0,0,0 --to 30,40,0 " + quote(mesh), dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(r.out)["measurements"][0];
  EXPECT_NEAR(j["value_mm"].get<double>(), 50.0, 1e-12);
  EXPECT_EQ(j["kind"], "distance");
  EXPECT_EQ(j["path"].size(), 2u);
}

TEST(MeasureCli, SurfaceLengthsAndTheAutomaticSet) {
  const std::string dir = testing::temp_dir();
  const std::string mesh = dir + "/body.ply";
  ASSERT_TRUE(write_ply(mesh, torso_and_arm()).ok());
  // Up the torso's back, 200 mm: a straight line on the wall.
  CliResult r = bodyscan("measure " + quote(mesh) + " --surface 0,150,-150 --to 0,350,-150", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json m = nlohmann::json::parse(r.out)["measurements"][0];
  EXPECT_EQ(m["kind"], "surface_length");
  EXPECT_NEAR(m["value_mm"].get<double>(), 200.0, 0.05);
  EXPECT_NEAR(m["straight_mm"].get<double>(), 200.0, 0.05);
  EXPECT_GE(m["path"].size(), 2u);
  EXPECT_EQ(m["crosses_filled_hole"], false);
  EXPECT_EQ(m["fill_bound_mm"], 0.0);
  EXPECT_EQ(m["estimated"], false);

  // The whole set on the shipped demo body: the document the scan job writes.
  const std::string body = BODYSCAN_SOURCE_DIR "/hw/sim/bodies/male_average.ply";
  r = bodyscan("measure " + quote(body) + " --auto", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["schema"], "bodyscan.measurements/1");
  EXPECT_EQ(j["algorithm"], "iso8559-auto-16");
  EXPECT_NEAR(j["floor_y_mm"].get<double>(), 0.0, 1e-3);
  EXPECT_TRUE(j["skipped"].empty());
  EXPECT_GE(j["landmarks"].size(), 20u);
  bool waist = false;
  for (const nlohmann::json& x : j["measurements"]) {
    EXPECT_FALSE(x["name"].get<std::string>().empty());
    EXPECT_GT(x["value_mm"].get<double>(), 0);
    EXPECT_FALSE(x["path"].empty()) << x["name"];
    if (x["name"] == "waist_girth") {
      waist = true;
      EXPECT_EQ(x["iso_clause"], "5.3.10");
      EXPECT_EQ(x["closed"], true);
      EXPECT_TRUE(x.contains("plane"));
      EXPECT_NEAR(x["value_mm"].get<double>(), 745, 6);  // the manifest's waist
    }
  }
  EXPECT_TRUE(waist);
  // A floor given: heights grow by the gap, girths stay.
  r = bodyscan("measure " + quote(body) + " --auto --floor -10", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  bool stature_seen = false;
  const nlohmann::json lowered = nlohmann::json::parse(r.out);  // kept: a range-for over a temporary's member dangles
  for (const nlohmann::json& x : lowered["measurements"]) {
    if (x["name"] != "stature") continue;
    stature_seen = true;
    EXPECT_NEAR(x["value_mm"].get<double>(), 1729.3 + 10, 0.1);
  }
  EXPECT_TRUE(stature_seen);

  // What cannot be done says why.
  r = bodyscan("measure " + quote(mesh) + " --auto", dir);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("measure:"), std::string::npos) << r.err;
  r = bodyscan("measure " + quote(mesh) + " --floor 0 --girth-y 300", dir);
  EXPECT_EQ(r.exit_code, 2);
  r = bodyscan("measure " + quote(mesh) + " --surface 0,0,0", dir);  // no --to
  EXPECT_EQ(r.exit_code, 2);
}

TEST(MeasureCli, BadInputIsAClearError) {
  const std::string dir = testing::temp_dir();
  const std::string mesh = dir + "/body.ply";
  ASSERT_TRUE(write_ply(mesh, torso_and_arm()).ok());
  CliResult r = bodyscan("measure " + quote(mesh) + " --girth-y 900", dir);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("does not cut"), std::string::npos) << r.err;
  r = bodyscan("measure " + quote(dir + "/missing.ply") + " --girth-y 300", dir);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("missing.ply"), std::string::npos) << r.err;
  r = bodyscan("measure " + quote(mesh) + " --girth-y abc", dir);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--girth-y"), std::string::npos) << r.err;
  r = bodyscan("measure " + quote(mesh) + " --plane 0,300,0,0,0,0", dir);
  EXPECT_EQ(r.exit_code, 2);
  r = bodyscan("measure " + quote(mesh), dir);
  EXPECT_EQ(r.exit_code, 2);
  r = bodyscan("measure " + quote(mesh) + " --girth-y 300 --plane 0,300,0,0,1,0", dir);
  EXPECT_EQ(r.exit_code, 2);
  r = bodyscan("measure " + quote(mesh) + " --girth-y 300 --arc 0,300,150", dir);  // no --to
  EXPECT_EQ(r.exit_code, 2);
  // A point in metres or garbage, 10 km off: refused, naming the option.
  r = bodyscan("measure " + quote(mesh) + " --girth-y 300 --near 0,300,1e7", dir);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--near is outside the scan volume"), std::string::npos) << r.err;
  r = bodyscan("measure " + quote(mesh) + " --surface 0,150,-150 --to 0,350,-1e7", dir);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--to is outside the scan volume"), std::string::npos) << r.err;
  std::ofstream(dir + "/broken.ply") << "ply\nformat ascii 1.0\nelement vertex 3\n";
  r = bodyscan("measure " + quote(dir + "/broken.ply") + " --girth-y 300", dir);
  EXPECT_EQ(r.exit_code, 1);
}

}  // namespace
}  // namespace bodyscan
