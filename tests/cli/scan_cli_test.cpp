// `bodyscan scan` as a user runs it.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "recon/io/ply.hpp"
#include "tests/cli/cli_runner.hpp"
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
  r = bodyscan("scan --out x", dir);
  EXPECT_EQ(r.exit_code, 2);
}

}  // namespace
}  // namespace bodyscan
