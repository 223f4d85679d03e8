#include <gtest/gtest.h>

#include <limits>

#include "sg/core/error.hpp"
#include "sg/core/params.hpp"

namespace sg::core {
namespace {

bool mentions(const std::vector<std::string>& problems, const std::string& text) {
  for (const auto& p : problems)
    if (p.find(text) != std::string::npos) return true;
  return false;
}

TEST(Params, DefaultsAreValid) {
  EXPECT_TRUE(validate(DetectorParams{}, Camera{}).empty());
}

TEST(Params, EvenBlockSizeIsRejected) {
  DetectorParams p;
  p.bm.block_size = 10;
  EXPECT_TRUE(mentions(validate(p, Camera{}), "stereo.block_size=10"));
}

TEST(Params, LongSeqMatcherRulesNameTheirFields) {
  EXPECT_EQ(parse_matcher("longseq"), Matcher::kLongSeq);
  EXPECT_STREQ(to_string(Matcher::kLongSeq), "longseq");
  DetectorParams p;
  p.bm.matcher = Matcher::kLongSeq;
  EXPECT_TRUE(validate(p, Camera{}).empty());
  p.bm.block_size = 65;
  p.bm.min_disparity = 16;
  p.bm.longseq_cost_max = 300;
  p.bm.longseq_best_max = -1;
  const std::vector<std::string> problems = validate(p, Camera{});
  EXPECT_TRUE(mentions(problems, "stereo.block_size=65: must be <= 63 with matcher longseq"));
  EXPECT_TRUE(mentions(problems, "stereo.min_disparity=16: must be 0 with matcher longseq"));
  EXPECT_TRUE(mentions(problems, "stereo.longseq_cost_max=300"));
  EXPECT_TRUE(mentions(problems, "stereo.longseq_best_max=-1"));
  // The same block is fine for the block matchers.
  p.bm.matcher = Matcher::kBm;
  EXPECT_FALSE(mentions(validate(p, Camera{}), "matcher longseq"));
  EXPECT_THROW(parse_matcher("long-seq"), InputError);
}

TEST(Params, NumDisparitiesMustBePositiveMultipleOf16) {
  for (int n : {0, -16, 70}) {
    DetectorParams p;
    p.bm.num_disparities = n;
    EXPECT_TRUE(mentions(validate(p, Camera{}), "stereo.num_disparities=" + std::to_string(n)))
        << n;
  }
}

TEST(Params, NumDisparitiesMustFitTheImage) {
  DetectorParams p;
  p.bm.num_disparities = 640;
  EXPECT_TRUE(mentions(validate(p, Camera{}), "below the image width"));
}

TEST(Params, HysteresisAndSeverityRules) {
  SignalParams s;
  s.on_k = 4;
  s.on_n = 3;
  s.ttc_warning_s = 1.0;
  const auto problems = validate(s);
  EXPECT_TRUE(mentions(problems, "signal.on_k=4"));
  EXPECT_TRUE(mentions(problems, "signal.ttc_warning_s=1"));
}

TEST(Params, ThrowIfInvalidJoinsProblems) {
  EXPECT_NO_THROW(throw_if_invalid({}, "ctx"));
  try {
    throw_if_invalid({"a", "b"}, "invalid parameters");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "invalid parameters: a; b");
  }
}

TEST(Params, ParseMode) {
  EXPECT_EQ(parse_mode("stereo"), Mode::kStereo);
  EXPECT_EQ(parse_mode("stereo-flow"), Mode::kStereoFlow);
  EXPECT_THROW(parse_mode("mono"), InputError);
}

TEST(Params, FlowAndSceneFlowAreValidated) {
  DetectorParams p;
  p.flow.method = FlowMethod::kFarneback;
  p.flow.fb_poly_n = 6;
  p.scene_flow.gaps = {1, 0};
  p.scene_flow.edge_margin_px = -1;
  p.scene_flow.exclude_ground = true;
  p.scene_flow.ground.lower_fraction = 0.0;
  p.scene_flow.startup_doubt_px = -0.1;
  p.scene_flow.surface_bridge_m = std::numeric_limits<double>::quiet_NaN();
  const auto problems = validate(p, Camera{});
  EXPECT_TRUE(mentions(problems, "scene_flow.startup_doubt_px=-0.1"));
  EXPECT_TRUE(mentions(problems, "scene_flow.surface_bridge_m=nan"));
  EXPECT_TRUE(mentions(problems, "flow.fb_poly_n=6"));
  EXPECT_TRUE(mentions(problems, "scene_flow.gaps=0"));
  EXPECT_TRUE(mentions(problems, "scene_flow.edge_margin_px=-1"));
  EXPECT_TRUE(mentions(problems, "ground.lower_fraction=0"));
  // Farneback settings are not checked for DIS; the ground only when it is used.
  p.flow.method = FlowMethod::kDisFast;
  p.scene_flow.exclude_ground = false;
  const auto fewer = validate(p, Camera{});
  EXPECT_FALSE(mentions(fewer, "flow.fb_poly_n"));
  EXPECT_FALSE(mentions(fewer, "ground."));
}

TEST(Params, FlowMethodNames) {
  for (FlowMethod m : {FlowMethod::kDisUltrafast, FlowMethod::kDisFast, FlowMethod::kDisMedium,
                       FlowMethod::kFarneback})
    EXPECT_EQ(parse_flow_method(to_string(m)), m);
  EXPECT_THROW(parse_flow_method("DIS"), InputError);
}

}  // namespace
}  // namespace sg::core
