#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "sg/vision/left_band.hpp"
#include "sg/vision/stereo_bm.hpp"
#include "sg/vision/stereo_fast.hpp"
#include "synthetic.hpp"

namespace sg::vision {
namespace {

core::BmParams wide_range() {
  core::BmParams p;
  p.num_disparities = 96;  // the full range leaves columns < 95 + h invalid
  return p;
}

/// Fraction of the pixels of `rect` whose disparity is within 0.5 px of d.
double share_near(const cv::Mat& disp, cv::Rect rect, float d) {
  int near = 0;
  for (int y = rect.y; y < rect.y + rect.height; ++y)
    for (int x = rect.x; x < rect.x + rect.width; ++x)
      near += std::abs(disp.at<float>(y, x) - d) <= 0.5f;
  return static_cast<double>(near) / rect.area();
}

TEST(LeftBand, FindsTheFarSurfaceTheFullRangeCannotSearch) {
  const test::StereoPair pair = test::shifted_pair({240, 120}, 9.0f, 41);
  const core::BmParams p = wide_range();
  const int h = p.block_size / 2;
  cv::Mat disp;
  match_fast_rows(pair.left, pair.right, p, disp, cv::Range::all());
  const cv::Rect band(15 + h, h, p.num_disparities - 16, 120 - 2 * h);
  EXPECT_EQ(share_near(disp, band, 9.0f), 0.0) << "the full range's band is invalid";
  match_left_band_rows(match_fast_rows, pair.left, pair.right, p, disp, cv::Range::all());
  EXPECT_GE(share_near(disp, band, 9.0f), 0.95);
  // Left of the first strip nothing is matched.
  EXPECT_EQ(cv::countNonZero(disp.colRange(0, 15 + h) >= 0.0f), 0);
}

/// A texture repeating every `period` columns, the right image shifted by d (right x = left x + d).
test::StereoPair periodic_pair(cv::Size size, int period, int d, uint64_t seed) {
  const cv::Mat tile = test::texture({period, size.height}, seed, 1.0);
  cv::Mat wide;
  cv::repeat(tile, 1, (size.width + d) / period + 1, wide);
  test::StereoPair p;
  p.left = wide.colRange(0, size.width).clone();
  p.right = wide.colRange(d, d + size.width).clone();
  return p;
}

TEST(LeftBand, TheRightViewRejectsAliasesOfPointsBeyondAStripsRange) {
  // True disparity 40, period 30: strips of range 16 and 32 hold the alias 10 alone (unique,
  // wrong); a search over the full range sees 10, 40 and 70 cost the same.
  const test::StereoPair pair = periodic_pair({240, 80}, 30, 40, 45);
  core::BmParams p = wide_range();
  const auto wrong_in_band = [&](const core::BmParams& q) {
    cv::Mat disp(pair.left.size(), CV_32F, cv::Scalar(-1.0f));
    match_left_band_rows(match_fast_rows, pair.left, pair.right, q, disp, cv::Range::all());
    const cv::Mat band = disp.colRange(0, q.num_disparities - 1 + q.block_size / 2);
    return cv::countNonZero((band >= 0.0f) & (cv::abs(band - 40.0f) > 1.0f));
  };
  p.lr_max_diff = -1;  // no check at all: the aliases stand
  EXPECT_GT(wrong_in_band(p), 100);
  p.lr_max_diff = 1;
  EXPECT_EQ(wrong_in_band(p), 0);
}

TEST(LeftBand, LeavesEverythingRightOfTheBandAlone) {
  const test::StereoPair pair = test::scene_pair({240, 120}, 42);
  const core::BmParams p = wide_range();
  const int band_end = p.num_disparities - 1 + p.block_size / 2;
  cv::Mat disp(pair.left.size(), CV_32F, cv::Scalar(123.0f));
  match_left_band_rows(match_fast_rows, pair.left, pair.right, p, disp, cv::Range::all());
  EXPECT_EQ(cv::countNonZero(disp.colRange(band_end, disp.cols) != 123.0f), 0);
  EXPECT_GT(cv::countNonZero(disp.colRange(0, band_end) != 123.0f), 0);
}

TEST(LeftBand, TilesStitchBitIdenticalAndTheReferenceAgrees) {
  const test::StereoPair pair = test::scene_pair({200, 96}, 43);
  const core::BmParams p = wide_range();
  cv::Mat whole(pair.left.size(), CV_32F, cv::Scalar(-1.0f));
  match_left_band_rows(match_fast_rows, pair.left, pair.right, p, whole, cv::Range::all());
  cv::Mat stitched(pair.left.size(), CV_32F, cv::Scalar(-1.0f));
  for (int r0 = 0; r0 < 96; r0 += 30)
    match_left_band_rows(match_fast_rows, pair.left, pair.right, p, stitched,
                         cv::Range(r0, std::min(96, r0 + 30)));
  EXPECT_EQ(cv::countNonZero(whole != stitched), 0);
  cv::Mat reference(pair.left.size(), CV_32F, cv::Scalar(-1.0f));
  match_left_band_rows(match_fast_reference, pair.left, pair.right, p, reference,
                       cv::Range::all());
  EXPECT_EQ(cv::countNonZero(whole != reference), 0);
}

TEST(LeftBand, WorksWithStereoBmToo) {
  const test::StereoPair pair = test::shifted_pair({240, 120}, 9.0f, 44);
  const core::BmParams p = wide_range();
  cv::Mat disp;
  match_bm_rows(pair.left, pair.right, p, disp, cv::Range::all());
  match_left_band_rows(match_bm_rows, pair.left, pair.right, p, disp, cv::Range::all());
  const int h = p.block_size / 2;
  EXPECT_GE(share_near(disp, cv::Rect(15 + h, h + 1, p.num_disparities - 16, 120 - 2 * h - 2), 9.0f),
            0.95);
}

}  // namespace
}  // namespace sg::vision
