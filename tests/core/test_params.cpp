#include <gtest/gtest.h>

#include <cmath>
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

TEST(Params, PeriodicRatioIsAShareBelowOne) {
  for (double bad : {-0.1, 1.0, 2.0, std::nan("")}) {
    DetectorParams p;
    p.bm.periodic_ratio = bad;
    EXPECT_TRUE(mentions(validate(p, Camera{}), "stereo.periodic_ratio=")) << bad;
  }
  DetectorParams off;
  off.bm.periodic_ratio = 0.0;
  EXPECT_TRUE(validate(off, Camera{}).empty());
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

TEST(Params, DetectorsByNameWithWhatTheyNeed) {
  for (const Mode m : all_modes()) EXPECT_EQ(parse_mode(to_string(m)), m);
  EXPECT_EQ(all_modes().size(), 7u);
  EXPECT_EQ(parse_mode("motion-parallax"), Mode::kMotionParallax);
  const std::string message = [] {
    try {
      parse_mode("optic");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  }();
  EXPECT_NE(message.find("detector=optic: must be one of stereo, stereo-flow, motion-parallax, "
                         "relative-size, elevation-map, sceneflow-seg, longseq"),
            std::string::npos)
      << message;
  // Monocular detectors need no disparity; only the motion detectors need flow.
  EXPECT_FALSE(needs(Mode::kMotionParallax).disparity);
  EXPECT_TRUE(needs(Mode::kMotionParallax).flow);
  EXPECT_FALSE(needs(Mode::kRelativeSize).disparity);
  EXPECT_FALSE(needs(Mode::kRelativeSize).flow);
  EXPECT_TRUE(needs(Mode::kSceneFlowSeg).disparity && needs(Mode::kSceneFlowSeg).flow);
  EXPECT_TRUE(needs(Mode::kElevationMap).disparity && !needs(Mode::kElevationMap).flow);
  EXPECT_TRUE(needs(Mode::kStereoFlow).flow && !needs(Mode::kStereo).flow);
  EXPECT_TRUE(needs(Mode::kRelativeSize).left_image && needs(Mode::kSceneFlowSeg).left_image);
  EXPECT_FALSE(needs(Mode::kStereoFlow).left_image || needs(Mode::kElevationMap).left_image);
  int surveyed = 0;
  for (const Mode m : all_modes()) surveyed += is_surveyed(m);
  EXPECT_EQ(surveyed, 5);
  EXPECT_FALSE(is_surveyed(Mode::kStereo) || is_surveyed(Mode::kStereoFlow));
  // The longseq detector brings its matcher; another one is an error naming the field.
  DetectorParams p;
  select_detector(p, Mode::kLongSeq);
  EXPECT_EQ(p.bm.matcher, Matcher::kLongSeq);
  EXPECT_TRUE(validate(p, Camera{}).empty());
  p.bm.matcher = Matcher::kFast;
  EXPECT_TRUE(mentions(validate(p, Camera{}),
                       "stereo.matcher=fast: must be longseq with the longseq detector"));
}

TEST(Params, SurveyedDetectorRulesNameTheirFields) {
  DetectorParams p;
  p.motion_parallax.smooth_px = 4;
  p.motion_parallax.flow_min_px_s = 0;
  p.relative_size.gap_frames = 0;
  p.relative_size.ratio_test = 1.5;
  p.elevation.cell_m = -1;
  p.sceneflow_seg.grid_step_px = 0;
  p.sceneflow_seg.lambda = -2;
  p.proximity.alarm_distance_m = 0.3;
  std::vector<std::string> problems = validate(p, Camera{});
  for (const char* field :
       {"motion_parallax.smooth_px=4", "motion_parallax.flow_min_px_s=0",
        "relative_size.gap_frames=0", "relative_size.ratio_test=1.5", "elevation.cell_m=-1",
        "sceneflow_seg.grid_step_px=0", "sceneflow_seg.lambda=-2"})
    EXPECT_TRUE(mentions(problems, field)) << field;
  // The alarm distance must lie beyond the contact depth for the detectors that use it.
  EXPECT_FALSE(mentions(problems, "proximity.alarm_distance_m"));
  p.mode = Mode::kElevationMap;
  EXPECT_TRUE(mentions(validate(p, Camera{}),
                       "proximity.alarm_distance_m=0.3: must exceed envelope.z_contact_m"));
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
  s.confirm_frames = 0;
  const auto problems = validate(s);
  EXPECT_TRUE(mentions(problems, "signal.on_k=4"));
  EXPECT_TRUE(mentions(problems, "signal.ttc_warning_s=1"));
  EXPECT_TRUE(mentions(problems, "signal.confirm_frames=0"));
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
  p.scene_flow.ground.side_margin_px = -0.5;
  p.scene_flow.startup_doubt_se = -0.1;
  p.scene_flow.chain_outlier_px = -1.0;
  p.scene_flow.chain_outlier_fraction = std::numeric_limits<double>::infinity();
  p.scene_flow.surface_bridge_m = std::numeric_limits<double>::quiet_NaN();
  const auto problems = validate(p, Camera{});
  EXPECT_TRUE(mentions(problems, "scene_flow.startup_doubt_se=-0.1"));
  EXPECT_TRUE(mentions(problems, "scene_flow.chain_outlier_px=-1"));
  EXPECT_TRUE(mentions(problems, "scene_flow.chain_outlier_fraction=inf"));
  EXPECT_TRUE(mentions(problems, "scene_flow.surface_bridge_m=nan"));
  EXPECT_TRUE(mentions(problems, "flow.fb_poly_n=6"));
  EXPECT_TRUE(mentions(problems, "scene_flow.gaps=0"));
  EXPECT_TRUE(mentions(problems, "scene_flow.edge_margin_px=-1"));
  EXPECT_TRUE(mentions(problems, "ground.lower_fraction=0"));
  EXPECT_TRUE(mentions(problems, "ground.side_margin_px=-0.5"));
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
