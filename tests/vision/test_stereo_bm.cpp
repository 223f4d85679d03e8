#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <ostream>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>

#include "sg/vision/stereo_bm.hpp"
#include "synthetic.hpp"

namespace sg::vision {
namespace {

/// Fraction of valid pixels (>= 0) and, among them, the fraction within `tol` px of `d`.
std::pair<double, double> accuracy(const cv::Mat& disp, float d, float tol) {
  int valid = 0, close = 0;
  for (int y = 0; y < disp.rows; ++y)
    for (int x = 0; x < disp.cols; ++x) {
      const float v = disp.at<float>(y, x);
      if (v < 0) continue;
      ++valid;
      if (std::abs(v - d) <= tol) ++close;
    }
  const double total = static_cast<double>(disp.total());
  return {valid / total, valid ? static_cast<double>(close) / valid : 0.0};
}

bool identical(const cv::Mat& a, const cv::Mat& b) {
  // Bitwise, so that NaN or -0 differences would also show.
  if (a.size() != b.size() || a.type() != b.type()) return false;
  for (int y = 0; y < a.rows; ++y)
    if (std::memcmp(a.ptr(y), b.ptr(y), a.cols * a.elemSize()) != 0) return false;
  return true;
}

TEST(StereoBm, OutputIsFloatOfImageSize) {
  const auto pair = test::shifted_pair({97, 53}, 5.0f, 1);
  core::BmParams p;
  p.num_disparities = 32;
  cv::Mat disp;
  match_bm(pair.left, pair.right, p, disp);
  EXPECT_EQ(disp.type(), CV_32FC1);
  EXPECT_EQ(disp.size(), pair.left.size());
}

TEST(StereoBm, ConstantIntegerShiftIsRecovered) {
  const auto pair = test::shifted_pair({331, 247}, 7.0f, 2);
  cv::Mat disp;
  match_bm(pair.left, pair.right, core::BmParams{}, disp);
  const auto [valid, close] = accuracy(disp, 7.0f, 0.25f);
  EXPECT_GT(valid, 0.6);  // borders (left ndisp + block/2, block/2 rows) are invalid
  EXPECT_GT(close, 0.95);
}

TEST(StereoBm, ConstantFractionalShiftIsRecovered) {
  const auto pair = test::shifted_pair({331, 247}, 10.5f, 3);
  cv::Mat disp;
  match_bm(pair.left, pair.right, core::BmParams{}, disp);
  const auto [valid, close] = accuracy(disp, 10.5f, 0.25f);
  EXPECT_GT(valid, 0.6);
  EXPECT_GT(close, 0.8);
}

TEST(StereoBm, InvalidBordersAreMinusOne) {
  const auto pair = test::shifted_pair({201, 101}, 7.0f, 4);
  core::BmParams p;
  cv::Mat disp;
  match_bm(pair.left, pair.right, p, disp);
  // The first min_disparity + num_disparities - 1 + block/2 columns cannot be matched.
  const int dead = p.min_disparity + p.num_disparities - 1 + p.block_size / 2;
  for (int y = 0; y < disp.rows; ++y)
    for (int x = 0; x < dead; ++x) ASSERT_EQ(disp.at<float>(y, x), -1.0f) << x << "," << y;
  for (int x = 0; x < disp.cols; ++x) EXPECT_EQ(disp.at<float>(0, x), -1.0f);
}

TEST(StereoBm, TexturelessImageIsAllInvalid) {
  const cv::Mat flat(123, 211, CV_8U, cv::Scalar(117));
  cv::Mat disp;
  match_bm(flat, flat, core::BmParams{}, disp);
  double lo = 0, hi = 0;
  cv::minMaxLoc(disp, &lo, &hi);
  EXPECT_LT(hi, 0.0);
  EXPECT_EQ(lo, -1.0);
}

TEST(StereoBm, MinDisparityOffsetIsRespected) {
  const auto pair = test::shifted_pair({331, 247}, 12.0f, 5);
  core::BmParams p;
  p.min_disparity = 8;
  p.num_disparities = 16;  // searches 8..23
  cv::Mat disp;
  match_bm(pair.left, pair.right, p, disp);
  const auto [valid, close] = accuracy(disp, 12.0f, 0.25f);
  EXPECT_GT(valid, 0.6);
  EXPECT_GT(close, 0.95);
  for (int y = 0; y < disp.rows; ++y)
    for (int x = 0; x < disp.cols; ++x) {
      const float v = disp.at<float>(y, x);
      ASSERT_TRUE(v == -1.0f || (v >= 8.0f && v < 24.0f)) << v;
    }

  // A shift below the searched range cannot be found.
  p.min_disparity = 16;
  match_bm(pair.left, pair.right, p, disp);
  EXPECT_LT(accuracy(disp, 12.0f, 0.25f).second, 0.05);
}

TEST(StereoBm, MatchesOpenCvStereoBmWithItsSpeckleFilter) {
  // Our match_bm = raw BM + filter_speckles should be OpenCV's own StereoBM (x-Sobel prefilter,
  // speckle filter inside), converted to px.
  const auto pair = test::scene_pair({331, 247}, 6);
  core::BmParams p;
  p.lr_max_diff = 1;
  cv::Mat ours;
  match_bm(pair.left, pair.right, p, ours);

  auto bm = cv::StereoBM::create(p.num_disparities, p.block_size);
  bm->setPreFilterType(cv::StereoBM::PREFILTER_XSOBEL);
  bm->setPreFilterCap(p.prefilter_cap);
  bm->setTextureThreshold(p.texture_threshold);
  bm->setUniquenessRatio(p.uniqueness_ratio);
  bm->setSpeckleWindowSize(p.speckle_window);
  bm->setSpeckleRange(p.speckle_range * 16);
  bm->setDisp12MaxDiff(p.lr_max_diff);
  cv::Mat raw;
  bm->compute(pair.left, pair.right, raw);
  int speckled = 0;
  for (int y = 0; y < raw.rows; ++y)
    for (int x = 0; x < raw.cols; ++x) {
      const short r = raw.at<short>(y, x);
      const float expected = r < 0 ? -1.0f : r / 16.0f;
      ASSERT_EQ(ours.at<float>(y, x), expected) << x << "," << y;
    }
  // The scene must actually exercise the filter for this test to mean something.
  cv::Mat unfiltered;
  match_bm_rows(pair.left, pair.right, p, unfiltered, cv::Range::all());
  speckled = cv::countNonZero((unfiltered >= 0) & (ours < 0));
  EXPECT_GT(speckled, 0);
}

TEST(StereoBm, SpeckleFilterRemovesSmallIslands) {
  cv::Mat disp(41, 57, CV_32F, cv::Scalar(10.0f));
  disp(cv::Rect(20, 10, 4, 4)).setTo(30.0f);  // 16 px island, far from its surroundings
  disp(cv::Rect(0, 0, 5, 41)).setTo(-1.0f);
  core::BmParams p;
  p.speckle_window = 20;
  p.speckle_range = 2;
  filter_speckles(disp, p);
  EXPECT_EQ(disp.at<float>(11, 21), -1.0f);
  EXPECT_EQ(disp.at<float>(30, 40), 10.0f);
  EXPECT_EQ(disp.at<float>(5, 2), -1.0f);
  EXPECT_EQ(cv::countNonZero(disp < 0), 16 + 5 * 41);

  p.speckle_window = 0;  // disabled: nothing changes
  cv::Mat again(41, 57, CV_32F, cv::Scalar(10.0f));
  again(cv::Rect(20, 10, 4, 4)).setTo(30.0f);
  filter_speckles(again, p);
  EXPECT_EQ(again.at<float>(11, 21), 30.0f);
}

TEST(StereoBm, InputRowsCoverHaloAndStayInImage) {
  core::BmParams p;  // block 11 -> halo 5 + 1
  EXPECT_EQ(bm_input_rows(cv::Range::all(), p, 247), cv::Range(0, 247));
  EXPECT_EQ(bm_input_rows({100, 140}, p, 247), cv::Range(94, 146));
  EXPECT_EQ(bm_input_rows({101, 140}, p, 247), cv::Range(94, 146));  // start rounded to even
  EXPECT_EQ(bm_input_rows({0, 30}, p, 247), cv::Range(0, 36));
  EXPECT_EQ(bm_input_rows({230, 247}, p, 247), cv::Range(224, 247));
  EXPECT_EQ(bm_input_rows({246, 247}, p, 247), cv::Range(234, 247));  // >= block + 1 rows
  EXPECT_EQ(bm_input_rows({0, 1}, p, 247), cv::Range(0, 12));
}

/// Stitches T tiles of match_bm_rows into one map.
cv::Mat tiled(const test::StereoPair& pair, const core::BmParams& p, int tiles) {
  cv::Mat disp(pair.left.size(), CV_32F, cv::Scalar(12345.0f));
  for (int t = 0; t < tiles; ++t) {
    const cv::Range rows(t * disp.rows / tiles, (t + 1) * disp.rows / tiles);
    match_bm_rows(pair.left, pair.right, p, disp, rows);
  }
  return disp;
}

struct TileCase {
  cv::Size size;
  int block;
  int min_disparity;
  int lr_max_diff;
};

void PrintTo(const TileCase& c, std::ostream* os) {
  *os << c.size.width << "x" << c.size.height << " block " << c.block << " min_disparity "
      << c.min_disparity << " lr_max_diff " << c.lr_max_diff;
}

class StereoBmTiles : public ::testing::TestWithParam<TileCase> {};

TEST_P(StereoBmTiles, StitchedTilesAreBitIdenticalToWholeImage) {
  const TileCase c = GetParam();
  const auto pair = test::scene_pair(c.size, 11);
  core::BmParams p;
  p.block_size = c.block;
  p.min_disparity = c.min_disparity;
  p.lr_max_diff = c.lr_max_diff;
  cv::Mat whole;
  match_bm_rows(pair.left, pair.right, p, whole, cv::Range::all());
  ASSERT_GT(cv::countNonZero(whole >= 0), static_cast<int>(whole.total() / 3));
  for (int tiles = 1; tiles <= 8; ++tiles) {
    const cv::Mat stitched = tiled(pair, p, tiles);
    EXPECT_TRUE(identical(stitched, whole)) << tiles << " tiles";
    // And the speckle filter over the stitched map gives match_bm.
    cv::Mat filtered = stitched.clone(), reference;
    filter_speckles(filtered, p);
    match_bm(pair.left, pair.right, p, reference);
    EXPECT_TRUE(identical(filtered, reference)) << tiles << " tiles";
  }
}

INSTANTIATE_TEST_SUITE_P(
    OddSizes, StereoBmTiles,
    ::testing::Values(TileCase{{331, 247}, 11, 0, -1}, TileCase{{331, 247}, 5, 0, 1},
                      TileCase{{331, 247}, 21, 3, -1}, TileCase{{331, 248}, 15, 0, 0},
                      TileCase{{640, 480}, 11, 0, -1}, TileCase{{181, 61}, 9, 0, 1}));

TEST(StereoBm, SingleRowTilesAreBitIdentical) {
  const auto pair = test::scene_pair({151, 47}, 12);
  core::BmParams p;
  p.num_disparities = 32;
  cv::Mat whole;
  match_bm_rows(pair.left, pair.right, p, whole, cv::Range::all());
  EXPECT_TRUE(identical(tiled(pair, p, pair.left.rows), whole));
}

TEST(StereoBm, NonContinuousRoiInputsAndOutput) {
  const auto pair = test::scene_pair({331, 247}, 13);
  core::BmParams p;
  cv::Mat whole;
  match_bm(pair.left, pair.right, p, whole);

  // The same images as windows of larger buffers, and the output into a window of a larger map.
  cv::Mat big_l(260, 350, CV_8U, cv::Scalar(0)), big_r(260, 350, CV_8U, cv::Scalar(0));
  const cv::Rect roi(9, 5, 331, 247);
  pair.left.copyTo(big_l(roi));
  pair.right.copyTo(big_r(roi));
  cv::Mat big_d(260, 350, CV_32F, cv::Scalar(7.0f));
  cv::Mat out = big_d(roi);
  ASSERT_FALSE(out.isContinuous());
  for (int t = 0; t < 3; ++t)
    match_bm_rows(big_l(roi), big_r(roi), p, out, {t * 247 / 3, (t + 1) * 247 / 3});
  filter_speckles(out, p);
  EXPECT_EQ(out.data, big_d(roi).data);  // written in place, not reallocated
  EXPECT_TRUE(identical(out.clone(), whole));
  EXPECT_EQ(big_d.at<float>(0, 0), 7.0f);
}

TEST(StereoBm, ResultDoesNotDependOnOpenCvThreadCount) {
  const auto pair = test::scene_pair({640, 480}, 14);
  core::BmParams p;
  p.lr_max_diff = 1;
  const int threads = cv::getNumThreads();
  cv::Mat many, one, one_tiled;
  match_bm(pair.left, pair.right, p, many);
  cv::setNumThreads(1);
  match_bm(pair.left, pair.right, p, one);
  one_tiled = tiled(pair, p, 5);
  cv::setNumThreads(threads);
  filter_speckles(one_tiled, p);
  EXPECT_TRUE(identical(many, one));
  EXPECT_TRUE(identical(many, one_tiled));
}

}  // namespace
}  // namespace sg::vision
