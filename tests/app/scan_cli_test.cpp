// `bodyscan scan` as a user runs it.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "recon/io/ply.hpp"
#include "tests/app/cli_runner.hpp"
#include "tests/test_data.hpp"

namespace bodyscan {
namespace {

TEST(ScanCli, CalibratesScansAndWritesTheCloudAndFigures) {
  const std::string dir = testing::temp_dir();
  const CliResult r = bodyscan("scan --rig sim --out " + quote(dir + "/scan") + " --every 12 --no-surface", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("calibration: lens"), std::string::npos) << "progress by stage: " << r.err;
  EXPECT_NE(r.out.find("camera back"), std::string::npos) << r.out;
  auto cloud = read_ply(dir + "/scan/points.ply");
  ASSERT_TRUE(cloud.ok()) << cloud.status().message();
  const nlohmann::json cal = nlohmann::json::parse(slurp(dir + "/scan/calibration.json"));
  ASSERT_EQ(cal["cameras"].size(), 3u);
  EXPECT_EQ(cal["cameras"][2]["side"], "back");
  const nlohmann::json scan = nlohmann::json::parse(slurp(dir + "/scan/scan.json"));
  EXPECT_GT(scan["points"].get<size_t>(), 5000u);
  EXPECT_FALSE(std::filesystem::exists(dir + "/scan/mesh.ply"));  // --no-surface
  EXPECT_EQ(scan["points_grazing"].get<size_t>(), 0u);            // off by default
  EXPECT_TRUE(cloud->cloud.normals.empty());
  // Every 12th step leaves the stripes 42 mm apart: too far to tell sway from shape.
  EXPECT_FALSE(scan.contains("sway"));
  EXPECT_NE(scan.value("sway_not_estimated", "").find("stripes are"), std::string::npos) << scan.dump(1);
  EXPECT_NE(r.out.find("sway: not estimated"), std::string::npos) << r.out;

  // --max-view drops what the cameras saw edge-on and leaves normals facing them.
  const CliResult v =
      bodyscan("scan --rig sim --out " + quote(dir + "/view") + " --every 12 --no-surface --max-view 60", dir);
  ASSERT_EQ(v.exit_code, 0) << v.err;
  const nlohmann::json vs = nlohmann::json::parse(slurp(dir + "/view/scan.json"));
  EXPECT_GT(vs["points_grazing"].get<size_t>(), 100u);
  auto viewed_ply = read_ply(dir + "/view/points.ply");
  ASSERT_TRUE(viewed_ply.ok()) << viewed_ply.status().message();
  const PointCloud* viewed = &viewed_ply->cloud;
  ASSERT_EQ(viewed->normals.size(), viewed->size());
  ASSERT_TRUE(viewed->has_cameras());
  size_t facing = 0;
  for (size_t i = 0; i < viewed->size(); ++i) {
    const Vec3f to_camera =
        (viewed->camera_centres[static_cast<size_t>(viewed->camera[i])] - viewed->positions[i]).normalized();
    facing += viewed->normals[i].dot(to_camera) >= std::cos(60.5 * M_PI / 180);
  }
  EXPECT_EQ(facing, viewed->size());
}

// The person holding the dot grid answers on the terminal: a request per camera
// and one to clear the rig, each answered by a line; nobody there (standard
// input closed) stops the scan before anything is written.
TEST(ScanCli, AsksOnTheTerminalForTheDotGrid) {
  const std::string dir = testing::temp_dir();
  const CliResult r = bodyscan(
      "scan --rig sim --out " + quote(dir + "/scan") + " --every 24 --no-surface --operator-dot-grid", dir, "\n\n\n\n");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  size_t holds = 0;
  for (size_t at = r.err.find("Hold the dot-grid board"); at != std::string::npos;
       at = r.err.find("Hold the dot-grid board", at + 1))
    ++holds;
  EXPECT_EQ(holds, 3u) << r.err;
  for (const char* camera : {"'front-left'", "'front-right'", "'back'"})
    EXPECT_NE(r.err.find(camera), std::string::npos);
  EXPECT_NE(r.err.find("Take the dot-grid board out of the rig"), std::string::npos) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir + "/scan/points.ply"));

  const CliResult nobody =
      bodyscan("scan --rig sim --out " + quote(dir + "/none") + " --every 24 --no-surface --operator-dot-grid", dir);
  EXPECT_EQ(nobody.exit_code, 1);
  EXPECT_NE(nobody.err.find("nobody answered"), std::string::npos) << nobody.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/none/points.ply"));
}

TEST(ScanCli, BadArgumentsAreClearErrors) {
  const std::string dir = testing::temp_dir();
  CliResult r = bodyscan("scan --rig sim --out x --every 0", dir);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--every"), std::string::npos) << r.err;
  r = bodyscan("scan --rig hexagon --out x", dir);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("hexagon"), std::string::npos) << r.err;
  r = bodyscan("scan --rig sim --out x --method guess", dir);
  EXPECT_EQ(r.exit_code, 2);
  r = bodyscan("scan --rig sim --out x --max-view 120", dir);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--max-view"), std::string::npos) << r.err;
  r = bodyscan("scan --out x", dir);
  EXPECT_EQ(r.exit_code, 2);
}

}  // namespace
}  // namespace bodyscan
