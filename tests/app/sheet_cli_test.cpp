// `bodyscan sheet` as a user runs it: a body mesh to its measurement sheet.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

#include "tests/app/cli_runner.hpp"
#include "tests/test_data.hpp"

namespace bodyscan {
namespace {

const std::string kBody = BODYSCAN_SOURCE_DIR "/hw/sim/bodies/female_average.ply";

TEST(SheetCli, WritesPdfCsvAndJsonInTheUnitAsked) {
  const std::string dir = testing::temp_dir();
  const CliResult pdf = bodyscan("sheet " + quote(kBody) + " -o " + quote(dir + "/s.pdf") +
                                     " --customer C-7 --scan s1 --date 2026-11-22 --operator Ana",
                                 dir);
  ASSERT_EQ(pdf.exit_code, 0) << pdf.err;
  EXPECT_NE(pdf.out.find("34 measurements in cm"), std::string::npos) << pdf.out;
  EXPECT_EQ(slurp(dir + "/s.pdf").rfind("%PDF-", 0), 0u);

  const CliResult csv = bodyscan("sheet " + quote(kBody) + " --unit in -o " + quote(dir + "/s.csv"), dir);
  ASSERT_EQ(csv.exit_code, 0) << csv.err;
  const std::string text = slurp(dir + "/s.csv");
  EXPECT_EQ(text.rfind("iso_clause,name,", 0), 0u);
  EXPECT_NE(text.find("5.3.10,waist_girth,Waist girth,"), std::string::npos) << text;
  EXPECT_NE(text.find(",in,"), std::string::npos);

  const CliResult js = bodyscan("sheet " + quote(kBody) + " --unit mm -o " + quote(dir + "/s.json"), dir);
  ASSERT_EQ(js.exit_code, 0) << js.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(dir + "/s.json"));
  EXPECT_EQ(j["unit"], "mm");
  EXPECT_EQ(j["measurements"].size(), 34u);
}

TEST(SheetCli, ErrorsAreClear) {
  const std::string dir = testing::temp_dir();
  EXPECT_EQ(bodyscan("sheet " + quote(kBody) + " -o " + quote(dir + "/s.docx"), dir).exit_code, 2);
  const CliResult unit = bodyscan("sheet " + quote(kBody) + " --unit furlong -o " + quote(dir + "/s.csv"), dir);
  EXPECT_EQ(unit.exit_code, 2);
  EXPECT_NE(unit.err.find("furlong"), std::string::npos) << unit.err;
  const CliResult missing = bodyscan("sheet " + quote(dir + "/nope.ply") + " -o " + quote(dir + "/s.csv"), dir);
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("nope.ply"), std::string::npos) << missing.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/s.csv"));
}

}  // namespace
}  // namespace bodyscan
