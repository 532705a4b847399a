#include "core/json_text.hpp"

#include <gtest/gtest.h>

#include <string>

namespace bodyscan {
namespace {

std::string nested(int depth, char open, char close) { return std::string(depth, open) + std::string(depth, close); }

TEST(JsonText, ParsesDocumentsUpToTheDepthLimit) {
  EXPECT_EQ(parse_json(R"({"a": [1, {"b": null}], "c": "d"})")["a"][1]["b"], nullptr);
  EXPECT_FALSE(parse_json(nested(kMaxJsonDepth, '[', ']')).is_discarded());
  EXPECT_TRUE(parse_json(nested(kMaxJsonDepth + 1, '[', ']')).is_discarded());
  EXPECT_TRUE(parse_json("{").is_discarded());
  EXPECT_TRUE(parse_json("").is_discarded());
}

// 400,000 levels (800 KB, under the server's 1 MiB body limit) once overflowed the
// stack where the parsed value was copied; now it is refused at parse time, and
// refusing it neither recurses nor builds the deep value.
TEST(JsonText, RefusesDeepNestingWithoutBuildingIt) {
  EXPECT_TRUE(parse_json(nested(400000, '[', ']')).is_discarded());
  std::string objects;
  for (int i = 0; i < 200000; ++i) objects += R"({"a":)";
  objects += "1" + std::string(200000, '}');
  EXPECT_TRUE(parse_json(objects).is_discarded());
  // A copy of the largest document allowed is cheap and safe.
  const nlohmann::json deepest = parse_json(nested(kMaxJsonDepth, '[', ']'));
  const nlohmann::json copy = deepest;
  EXPECT_EQ(copy, deepest);
}

}  // namespace
}  // namespace bodyscan
