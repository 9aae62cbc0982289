// Tests of the JSON entry point for untrusted input (json_input.h): deep nesting refused before
// any recursive code, numbers out of range named by their key, syntax errors without the tag.
#include "core/json_input.h"

#include <gtest/gtest.h>

#include <string>

#include "core/error.h"
#include "core/testing.h"

namespace eik {
namespace {

std::string errorOf(const std::string& text) {
  try {
    parseJsonInput(text, "in.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(JsonInput, ParsesOrdinaryDocuments) {
  const nlohmann::json j = parseJsonInput(R"({"a": [1, 2.5, {"b": "c"}], "d": null})", "in.json");
  EXPECT_EQ(j["a"][1], 2.5);
  EXPECT_EQ(j["a"][2]["b"], "c");
}

TEST(JsonInput, NestingDeeperThanTheLimitIsRefused) {
  // 10⁶ levels: copying or destroying such a document recursed once per level and overflowed the
  // stack; it is refused while parsing.
  for (const char* open : {"[", "{\"k\":"}) {
    std::string text;
    for (int i = 0; i < 1000000; ++i) text += open;
    const std::string e = errorOf(text);
    EXPECT_CONTAINS(e, "in.json: JSON: nested deeper than 256 levels");
  }
  std::string ok;  // exactly the limit parses (the top level counts as the first level)
  for (int i = 0; i < kMaxJsonDepth; ++i) ok += "[";
  for (int i = 0; i < kMaxJsonDepth; ++i) ok += "]";
  EXPECT_NO_THROW(parseJsonInput(ok, "in.json"));
  EXPECT_CONTAINS(errorOf("[" + ok + "]"), "nested deeper than 256 levels");
}

TEST(JsonInput, NumberOutOfRangeNamesItsKey) {
  EXPECT_CONTAINS(errorOf(R"({"grid": {"spacing": 1e999}})"), "in.json: spacing: number out of range");
  EXPECT_CONTAINS(errorOf("[1e999]"), "in.json: JSON: number out of range");
}

TEST(JsonInput, SyntaxErrorsKeepTheLineAndDropTheTag) {
  const std::string e = errorOf("{\"a\": 1,\n \"b\": }");
  EXPECT_CONTAINS(e, "in.json: JSON: parse error at line 2");
  EXPECT_EQ(e.find("[json.exception"), std::string::npos) << e;
}

}  // namespace
}  // namespace eik
