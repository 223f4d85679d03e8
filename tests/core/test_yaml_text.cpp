#include <gtest/gtest.h>

#include <string>

#include "sg/core/error.hpp"
#include "sg/core/yaml_text.hpp"

namespace sg::core {
namespace {

TEST(YamlText, FlowNestingCountsBracketsAndBraces) {
  EXPECT_EQ(flow_nesting_depth(""), 0);
  EXPECT_EQ(flow_nesting_depth("a: 1\nb: [1, 2]\n"), 1);
  EXPECT_EQ(flow_nesting_depth("{\"o\": [{\"a\": [[1, 2], [3]]}]}"), 5);
  EXPECT_EQ(flow_nesting_depth("[[[[3"), 4);  // unclosed brackets count
  EXPECT_EQ(flow_nesting_depth("]]]] [1]"), 1);
}

TEST(YamlText, FlowNestingSkipsQuotedScalarsAndComments) {
  EXPECT_EQ(flow_nesting_depth("a: '[[[['\nb: \"{{{{\"\n"), 0);
  EXPECT_EQ(flow_nesting_depth("a: 'it''s [[[['\n"), 0);        // '' inside '...'
  EXPECT_EQ(flow_nesting_depth("a: \"q\\\" [[[[\"\n"), 0);      // \" inside "..."
  EXPECT_EQ(flow_nesting_depth("# [[[[\na: [1] # {{{{\n"), 1);  // comments
  EXPECT_EQ(flow_nesting_depth("a: it's [1]\n"), 1);            // an apostrophe in a plain scalar
  EXPECT_EQ(flow_nesting_depth("a: b#[[[[\n"), 4);              // # inside a word is no comment
}

TEST(YamlText, CheckFlowNestingRefusesMoreThanTheLimit) {
  const std::string at_limit =
      std::string(kMaxFlowNesting, '[') + std::string(kMaxFlowNesting, ']');
  EXPECT_NO_THROW(check_flow_nesting(at_limit, "f.yaml"));
  const std::string deeper = "[" + at_limit + "]";
  try {
    check_flow_nesting(deeper, "f.yaml");
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "f.yaml: collections ([ ] or { }) nested more than 32 levels deep");
  }
}

}  // namespace
}  // namespace sg::core
