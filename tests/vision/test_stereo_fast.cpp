#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cmath>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "sg/vision/frame_kernels.hpp"
#include "sg/vision/stereo_fast.hpp"
#include "sg/vision/stereo_sgbm.hpp"
#include "synthetic.hpp"

namespace sg::vision {
namespace {

bool identical(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return false;
  for (int y = 0; y < a.rows; ++y)
    if (std::memcmp(a.ptr(y), b.ptr(y), a.cols * a.elemSize()) != 0) return false;
  return true;
}

/// Number of pixels where a and b differ (for a readable failure message).
int differences(const cv::Mat& a, const cv::Mat& b) {
  int n = 0;
  for (int y = 0; y < a.rows; ++y)
    for (int x = 0; x < a.cols; ++x) n += a.at<float>(y, x) != b.at<float>(y, x);
  return n;
}

/// scene_pair with sensor noise on the right image, so that costs tie rarely but do tie.
test::StereoPair noisy_scene(cv::Size size, uint64_t seed) {
  test::StereoPair p = test::scene_pair(size, seed);
  cv::Mat noise(size, CV_16S);
  cv::RNG rng(seed + 1);
  rng.fill(noise, cv::RNG::NORMAL, 0, 3);
  cv::Mat r16;
  p.right.convertTo(r16, CV_16S);
  cv::Mat(r16 + noise).convertTo(p.right, CV_8U);
  return p;
}

/// Every SIMD target this machine can run and this build compiled.
std::vector<int64_t> targets() { return hwy::SupportedAndGeneratedTargets(); }

/// Runs match_fast_rows once per dispatch target and expects each to equal `expected`.
void expect_all_targets_equal(const cv::Mat& left, const cv::Mat& right, const core::BmParams& p,
                              const cv::Mat& expected, const std::string& what) {
  for (int64_t target : targets()) {
    hwy::SetSupportedTargetsForTest(target);
    ASSERT_EQ(fast_matcher_target(), hwy::TargetName(target));
    cv::Mat disp;
    match_fast_rows(left, right, p, disp, cv::Range::all());
    EXPECT_TRUE(identical(disp, expected)) << what << " target " << hwy::TargetName(target) << ": "
                                           << differences(disp, expected) << " pixels differ";
  }
  hwy::SetSupportedTargetsForTest(0);
}

struct Case {
  const char* name;
  core::MatchCost cost;
  int min_disparity, num_disparities, block_size, uniqueness, texture, lr;
};

class FastVsReference : public ::testing::TestWithParam<Case> {};

core::BmParams params_of(const Case& c) {
  core::BmParams p;
  p.matcher = core::Matcher::kFast;
  p.cost = c.cost;
  p.min_disparity = c.min_disparity;
  p.num_disparities = c.num_disparities;
  p.block_size = c.block_size;
  p.uniqueness_ratio = c.uniqueness;
  p.texture_threshold = c.texture;
  p.lr_max_diff = c.lr;
  return p;
}

TEST_P(FastVsReference, BitIdenticalOnOddSizeOnEveryTarget) {
  const Case c = GetParam();
  const core::BmParams p = params_of(c);
  const auto pair = noisy_scene({631, 479}, 7);
  cv::Mat expected;
  match_fast_reference(pair.left, pair.right, p, expected, cv::Range::all());
  // The case must exercise both outcomes, or agreement would prove little.
  const int valid = cv::countNonZero(expected >= 0);
  EXPECT_GT(valid, static_cast<int>(expected.total() / 4));
  EXPECT_LT(valid, static_cast<int>(expected.total()));
  expect_all_targets_equal(pair.left, pair.right, p, expected, c.name);
}

INSTANTIATE_TEST_SUITE_P(
    CostsAndOptions, FastVsReference,
    ::testing::Values(Case{"sad_plain", core::MatchCost::kSad, 0, 32, 5, 0, 0, -1},
                      Case{"sad_defaults", core::MatchCost::kSad, 0, 32, 5, 15, 10, -1},
                      Case{"sad_lr", core::MatchCost::kSad, 0, 32, 7, 10, 10, 1},
                      Case{"sad_min_disp", core::MatchCost::kSad, 3, 16, 5, 15, 10, 0},
                      Case{"census_plain", core::MatchCost::kCensus, 0, 32, 5, 0, 0, -1},
                      Case{"census_defaults", core::MatchCost::kCensus, 0, 32, 5, 15, 10, -1},
                      Case{"census_lr", core::MatchCost::kCensus, 0, 32, 7, 10, 10, 1},
                      Case{"census_min_disp", core::MatchCost::kCensus, 3, 16, 5, 15, 10, 0}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(StereoFast, NonContinuousRoiInputsOnEveryTarget) {
  const auto pair = noisy_scene({300, 201}, 11);
  // Embed the images in wider and taller mats: the ROIs have a padded pitch.
  cv::Mat big_l(260, 371, CV_8U, cv::Scalar(0)), big_r(260, 371, CV_8U, cv::Scalar(255));
  const cv::Rect roi(37, 23, 300, 201);
  pair.left.copyTo(big_l(roi));
  pair.right.copyTo(big_r(roi));
  const cv::Mat l = big_l(roi), r = big_r(roi);
  ASSERT_FALSE(l.isContinuous());
  for (core::MatchCost cost : {core::MatchCost::kSad, core::MatchCost::kCensus}) {
    const core::BmParams p = params_of(Case{"", cost, 0, 32, 9, 15, 10, 1});
    cv::Mat expected;
    match_fast_reference(pair.left, pair.right, p, expected, cv::Range::all());
    expect_all_targets_equal(l, r, p, expected, core::to_string(cost));
    // A non-continuous output ROI is written in place.
    cv::Mat big_out(240, 350, CV_32F, cv::Scalar(7.0f));
    cv::Mat out = big_out(cv::Rect(10, 10, 300, 201));
    match_fast_rows(l, r, p, out, cv::Range::all());
    EXPECT_EQ(out.data, big_out.ptr(10) + 10 * sizeof(float));
    EXPECT_TRUE(identical(out, expected));
  }
}

TEST(StereoFast, StitchedTilesAreBitIdenticalToWholeImage) {
  const auto pair = noisy_scene({257, 190}, 3);
  for (core::MatchCost cost : {core::MatchCost::kSad, core::MatchCost::kCensus}) {
    const core::BmParams p = params_of(Case{"", cost, 0, 32, 11, 15, 10, 2});
    cv::Mat whole;
    match_fast_rows(pair.left, pair.right, p, whole, cv::Range::all());
    for (int tiles : {2, 3, 7, 190}) {
      cv::Mat stitched(whole.size(), CV_32F, cv::Scalar(99.0f));
      for (int t = 0; t < tiles; ++t) {
        const int r0 = whole.rows * t / tiles, r1 = whole.rows * (t + 1) / tiles;
        match_fast_rows(pair.left, pair.right, p, stitched, cv::Range(r0, r1));
      }
      EXPECT_TRUE(identical(stitched, whole)) << core::to_string(cost) << " tiles " << tiles;
    }
  }
}

TEST(StereoFast, ConstantShiftIsRecoveredWithBothCosts) {
  for (float shift : {9.0f, 12.5f}) {
    const auto pair = test::shifted_pair({160, 120}, shift, 5);
    for (core::MatchCost cost : {core::MatchCost::kSad, core::MatchCost::kCensus}) {
      core::BmParams p;
      p.matcher = core::Matcher::kFast;
      p.cost = cost;
      p.num_disparities = 32;
      cv::Mat disp;
      match_fast_rows(pair.left, pair.right, p, disp, cv::Range::all());
      int valid = 0, close = 0;
      for (int y = 0; y < disp.rows; ++y)
        for (int x = 0; x < disp.cols; ++x) {
          const float v = disp.at<float>(y, x);
          if (v < 0) continue;
          ++valid;
          close += std::abs(v - shift) <= 0.25f;
        }
      // Valid region: x in [31 + 5, 160 - 5), y in [5, 115): 119 x 110 px.
      EXPECT_GT(valid, 119 * 110 * 9 / 10) << core::to_string(cost) << " shift " << shift;
      EXPECT_GT(close, valid * 95 / 100) << core::to_string(cost) << " shift " << shift;
    }
  }
}

TEST(StereoFast, BordersAndTexturelessAreInvalid) {
  core::BmParams p;
  p.matcher = core::Matcher::kFast;
  p.num_disparities = 16;
  p.block_size = 7;
  const cv::Mat flat(60, 80, CV_8U, cv::Scalar(90));
  cv::Mat disp;
  match_fast_rows(flat, flat, p, disp, cv::Range::all());
  EXPECT_EQ(cv::countNonZero(disp != -1.0f), 0);
  const auto pair = test::shifted_pair({80, 60}, 4.0f, 2);
  match_fast_rows(pair.left, pair.right, p, disp, cv::Range::all());
  EXPECT_EQ(cv::countNonZero(disp.colRange(0, 15 + 3) != -1.0f), 0);  // search range + half block
  EXPECT_EQ(cv::countNonZero(disp.rowRange(0, 3) != -1.0f), 0);
  EXPECT_EQ(cv::countNonZero(disp.rowRange(57, 60) != -1.0f), 0);
  EXPECT_GT(cv::countNonZero(disp.rowRange(3, 57) >= 0.0f), 0);
}

TEST(StereoFast, FrameKernelsDispatchOnTheMatcher) {
  const auto pair = noisy_scene({200, 150}, 9);
  core::StereoFrame frame;
  frame.left = pair.left;
  frame.right = pair.right;
  core::DetectorParams params;
  params.bm.num_disparities = 32;
  params.bm.left_band = false;  // the matchers alone (LeftBand.* test the band)
  for (core::Matcher m : {core::Matcher::kFast, core::Matcher::kSgbm}) {
    params.bm.matcher = m;
    cv::Mat direct, whole, tiled(150, 200, CV_32F, cv::Scalar(5.0f));
    if (m == core::Matcher::kFast)
      match_fast_rows(pair.left, pair.right, params.bm, direct, cv::Range::all());
    else
      match_sgbm_rows(pair.left, pair.right, params.bm, direct, cv::Range::all());
    disparity_rows(frame, params, whole, cv::Range::all());
    EXPECT_TRUE(identical(whole, direct)) << core::to_string(m);
    // Tiles (sgbm: each one from a whole-image match) stitch to the whole image.
    for (int t = 0; t < 3; ++t)
      disparity_rows(frame, params, tiled, cv::Range(50 * t, 50 * t + 50));
    EXPECT_TRUE(identical(tiled, whole)) << core::to_string(m);
    EXPECT_GT(cv::countNonZero(whole >= 0), 200 * 150 / 4) << core::to_string(m);
  }
}

TEST(StereoFast, DispatchesToEachCompiledTarget) {
  // The machine this runs on decides the list; x86-64 has at least SSE4 or a scalar fallback.
  std::string names;
  for (int64_t target : targets()) names += std::string(hwy::TargetName(target)) + " ";
  std::cout << "fast matcher targets: " << names << "(default " << fast_matcher_target() << ")\n";
  EXPECT_FALSE(targets().empty());
}

TEST(StereoFast, SubpixelFollowsTheCheaperNeighbour) {
  EXPECT_EQ(subpixel_disparity16(10, 50, 20, 50), 160);  // symmetric: on the integer
  EXPECT_GT(subpixel_disparity16(10, 80, 20, 40), 160);  // cheaper at d + 1: above
  EXPECT_LT(subpixel_disparity16(10, 40, 20, 80), 160);  // cheaper at d - 1: below
  EXPECT_EQ(subpixel_disparity16(10, 60, 20, 20), 168);  // tie with d + 1: half a pixel
  EXPECT_EQ(subpixel_disparity16(3, 20, 20, 20), 48);    // flat: no offset
}

}  // namespace
}  // namespace sg::vision
