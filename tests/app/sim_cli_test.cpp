// `bodyscan sim render` as a user runs it.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>

#include "recon/io/png_image.hpp"
#include "tests/app/cli_runner.hpp"
#include "tests/test_data.hpp"

namespace bodyscan {
namespace {

TEST(SimCli, RendersCalibrationAndScanFramesWithAnIndex) {
  const std::string dir = testing::temp_dir();
  // Every 200th step: the first and one more per group.
  const CliResult r = bodyscan("sim render --rig thesis --out " + quote(dir + "/render") + " --every 200 -q", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json index = nlohmann::json::parse(slurp(dir + "/render/index.json"));
  EXPECT_EQ(index["rig"], "thesis");
  ASSERT_EQ(index["cameras"].size(), 3u);
  // Per camera: dot grid, room, frame lights off, on, front poles only, and per laser
  // (4) a base and the laser lit at both ends and the middle of its sweep; per laser
  // group (4, one laser each): base + 2 steps.
  EXPECT_EQ(index["images"].size(), 3u * (5 + 4 * 4) + 4u * 3 * 3);
  std::set<std::string> files;
  for (const auto& img : index["images"]) files.insert(img["file"].get<std::string>());
  EXPECT_EQ(files.size(), index["images"].size()) << "every image has its own file";
  uint64_t last_id = 0;
  for (const auto& img : index["images"]) {
    const std::string file = dir + "/render/" + img["file"].get<std::string>();
    ASSERT_TRUE(std::filesystem::exists(file)) << file;
    if (img["camera"] == "back") {
      EXPECT_GT(img["frame_id"].get<uint64_t>(), last_id);  // frames count up per camera
      last_id = img["frame_id"].get<uint64_t>();
    }
  }
  auto lit = read_png(dir + "/render/scan/front-left/group0_step0200.png");
  ASSERT_TRUE(lit.ok()) << lit.status().message();
  EXPECT_EQ(lit->width, 1280);
  EXPECT_EQ(lit->height, 1024);
  // The last group's laser at step 200 from its first.
  const auto& last = index["images"][index["images"].size() - 1];
  ASSERT_EQ(last["lasers"].size(), 1u);
  EXPECT_EQ(last["lasers"][0]["step"], -175 + 200);
}

TEST(SimCli, BadRigIsAClearError) {
  const std::string dir = testing::temp_dir();
  CliResult r = bodyscan("sim render --rig hexagon --out " + quote(dir + "/x"), dir);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no shipped rig named 'hexagon'"), std::string::npos) << r.err;
  std::ofstream(dir + "/bad.json") << "{\"frame\": {\"width\": 10}}";
  r = bodyscan("sim render --rig " + quote(dir + "/bad.json") + " --out " + quote(dir + "/x"), dir);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("missing field 'depth'"), std::string::npos) << r.err;
  r = bodyscan("sim render --out x", dir);
  EXPECT_EQ(r.exit_code, 2);
  r = bodyscan("sim render --rig thesis --out x --every 0", dir);
  EXPECT_EQ(r.exit_code, 2);
}

}  // namespace
}  // namespace bodyscan
