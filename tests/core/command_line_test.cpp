#include "core/command_line.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace bodyscan {
namespace {

// Parses `args` (argv without its first element) with stderr and stdout kept
// from the test's output; returns parse()'s answer.
std::optional<int> quietly(CommandLine& cl, const std::vector<std::string>& args, std::string* printed = nullptr) {
  testing::internal::CaptureStderr();
  testing::internal::CaptureStdout();
  const auto exit = cl.parse(args);
  const std::string err = testing::internal::GetCapturedStderr();
  const std::string out = testing::internal::GetCapturedStdout();
  if (printed) *printed = err + out;
  return exit;
}

TEST(CommandLine, BindsFlagsValuesAndPositionalsInAnyOrder) {
  bool quiet = false, fast = false;
  std::string file, out;
  double floor = 0;
  std::optional<double> sway;
  int every = 1;
  std::uint64_t seed = 0;
  std::vector<std::string> bodies;
  CommandLine cl("tool", "usage: tool FILE\n");
  cl.positional("FILE", &file);
  cl.flag("-q|--quiet", &quiet);
  cl.flag("--fast", &fast);
  cl.option("-o|--output", &out);
  cl.option("--floor", &floor);
  cl.option("--sway", &sway);
  cl.option("--every", &every);
  cl.option("--seed", &seed);
  cl.option("--body", &bodies);
  EXPECT_EQ(quietly(cl, {"--floor", "-12.5", "-q", "in.ply", "-o", "x.pdf", "--body", "a", "--every=3", "--body=b",
                         "--seed", "18446744073709551615"}),
            std::nullopt);
  EXPECT_TRUE(quiet);
  EXPECT_FALSE(fast);
  EXPECT_EQ(file, "in.ply");
  EXPECT_EQ(out, "x.pdf");
  EXPECT_EQ(floor, -12.5);  // a value may begin with '-'
  EXPECT_FALSE(sway.has_value());
  EXPECT_EQ(every, 3);
  EXPECT_EQ(seed, UINT64_MAX);
  EXPECT_EQ(bodies, (std::vector<std::string>{"a", "b"}));
}

TEST(CommandLine, HelpPrintsTheUsageAndExitsZero) {
  CommandLine cl("tool", "usage: tool [--fast]\n");
  bool fast = false;
  cl.flag("--fast", &fast);
  std::string printed;
  EXPECT_EQ(quietly(cl, {"--fast", "--help"}, &printed), 0);
  EXPECT_EQ(printed, "usage: tool [--fast]\n");
}

TEST(CommandLine, UsageErrorsSayWhatIsWrongAndExitTwo) {
  struct Case {
    std::vector<std::string> args;
    std::string says;
  };
  const std::vector<Case> cases = {
      {{"--nope"}, "tool: unknown option '--nope'"},
      {{"--every"}, "tool: --every needs a value"},
      {{"--every", "3x"}, "tool: --every expects an integer, got '3x'"},
      {{"--every", "99999999999"}, "tool: --every expects an integer"},
      {{"--floor", "nan"}, "tool: --floor expects a number, got 'nan'"},
      {{"--floor", ""}, "tool: --floor expects a number"},
      {{"--floor", "1e999"}, "tool: --floor expects a number"},
      {{"--fast=1"}, "tool: --fast takes no value"},
      {{"a", "b"}, "tool: unexpected argument 'b'"},
      {{"--port", "70000"}, "tool: --port expects a number from 0 to 65535, got '70000'"},
      {{}, "tool: missing FILE"},
  };
  for (const Case& c : cases) {
    std::string file;
    int every = 0, port = 0;
    double floor = 0;
    bool fast = false;
    CommandLine cl("tool", "usage: tool FILE\n");
    cl.positional("FILE", &file);
    cl.option("--every", &every);
    cl.option("--floor", &floor);
    cl.flag("--fast", &fast);
    cl.option("--port", integer_between(0, 65535, [&port](long long n) { port = static_cast<int>(n); }));
    std::string printed;
    EXPECT_EQ(quietly(cl, c.args, &printed), 2) << c.says;
    EXPECT_EQ(printed.rfind(c.says, 0), 0u) << printed;
    EXPECT_NE(printed.find("usage: tool FILE"), std::string::npos) << printed;
    EXPECT_EQ(port, 0);
  }
}

TEST(CommandLine, CustomParsersCheckTheirValue) {
  std::vector<double> point;
  CommandLine cl("tool", "usage\n");
  cl.option("--near", [&point](const std::string& v) -> std::string {
    auto x = parse_number_list(v, 3);
    if (!x) return "expects X,Y,Z";
    point = *x;
    return "";
  });
  std::string printed;
  EXPECT_EQ(quietly(cl, {"--near", "1,2"}, &printed), 2);
  EXPECT_EQ(printed.rfind("tool: --near expects X,Y,Z", 0), 0u) << printed;
  EXPECT_EQ(quietly(cl, {"--near", "1,-2,3.5"}), std::nullopt);
  EXPECT_EQ(point, (std::vector<double>{1, -2, 3.5}));
}

TEST(CommandLine, DoubleDashEndsTheOptionsAndRestTakesTheOthers) {
  std::string dir;
  std::vector<std::string> rest;
  bool yes = false;
  CommandLine cl("tool", "usage\n");
  cl.positional("DIR", &dir);
  cl.rest("ARGS", &rest);
  cl.flag("--yes", &yes);
  EXPECT_EQ(quietly(cl, {"d", "list", "--yes", "--", "--not-an-option", "-"}), std::nullopt);
  EXPECT_EQ(dir, "d");
  EXPECT_TRUE(yes);
  EXPECT_EQ(rest, (std::vector<std::string>{"list", "--not-an-option", "-"}));
}

TEST(CommandLine, FailAfterParsingPrintsLikeAParseError) {
  CommandLine cl("bodyscan sheet", "usage: bodyscan sheet\n");
  testing::internal::CaptureStderr();
  EXPECT_EQ(cl.fail("give a MESH.ply"), 2);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "bodyscan sheet: give a MESH.ply\nusage: bodyscan sheet\n");
}

TEST(NumberParsing, IsStrict) {
  EXPECT_EQ(parse_double("-1.5e2"), -150.0);
  EXPECT_EQ(parse_double(" 1"), std::nullopt);
  EXPECT_EQ(parse_double("1 "), std::nullopt);
  EXPECT_EQ(parse_double("inf"), std::nullopt);
  EXPECT_EQ(parse_integer("-42"), -42);
  EXPECT_EQ(parse_integer("4.2"), std::nullopt);
  EXPECT_EQ(parse_number_list("1,2,3", 3), (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(parse_number_list("1,,3"), std::nullopt);
  EXPECT_EQ(parse_number_list("1,2", 3), std::nullopt);
  EXPECT_EQ(parse_number_list(""), std::nullopt);
}

}  // namespace
}  // namespace bodyscan
