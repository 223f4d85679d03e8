#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "sg/eval/stereo_metrics.hpp"

namespace sg::eval {
namespace {

TEST(StereoMetrics, CountsSparseAndDenseOverGtValidPixels) {
  // 10 GT-valid pixels at 10 px; outputs: 4 exact, 1 off by 1.5, 1 off by 3, 1 off by 5, 3 missing.
  cv::Mat gt(2, 6, CV_32F, cv::Scalar(10.0f)), disp(2, 6, CV_32F, cv::Scalar(10.0f));
  gt.at<float>(1, 4) = 0;                                       // unknown GT
  gt.at<float>(1, 5) = std::numeric_limits<float>::infinity();  // unknown GT
  disp.at<float>(1, 4) = 99;                                    // ignored: no GT
  disp.at<float>(0, 4) = 11.5f;
  disp.at<float>(0, 5) = 7.0f;
  disp.at<float>(1, 0) = 15.0f;
  disp.at<float>(1, 1) = -1.0f;
  disp.at<float>(1, 2) = -1.0f;
  disp.at<float>(1, 3) = -1.0f;
  const StereoScores s = score_disparity(disp, gt);
  EXPECT_EQ(s.gt_pixels, 10);
  EXPECT_EQ(s.matched, 7);
  EXPECT_DOUBLE_EQ(s.density, 0.7);
  EXPECT_DOUBLE_EQ(s.bad1, 100.0 * 3 / 7);
  EXPECT_DOUBLE_EQ(s.bad2, 100.0 * 2 / 7);
  EXPECT_DOUBLE_EQ(s.bad4, 100.0 * 1 / 7);
  EXPECT_DOUBLE_EQ(s.dense_bad1, 60.0);
  EXPECT_DOUBLE_EQ(s.dense_bad2, 50.0);
  EXPECT_DOUBLE_EQ(s.dense_bad4, 40.0);
  EXPECT_DOUBLE_EQ(s.mae, (1.5 + 3.0 + 5.0) / 7);
}

TEST(StereoMetrics, ThresholdIsStrictlyGreater) {
  cv::Mat gt(1, 2, CV_32F, cv::Scalar(4.0f)), disp(1, 2, CV_32F);
  disp.at<float>(0, 0) = 6.0f;  // off by exactly 2: not bad-2
  disp.at<float>(0, 1) = 2.0f;
  const StereoScores s = score_disparity(disp, gt);
  EXPECT_DOUBLE_EQ(s.bad1, 100.0);
  EXPECT_DOUBLE_EQ(s.bad2, 0.0);
}

TEST(StereoMetrics, NoGtGivesZeros) {
  const StereoScores s = score_disparity(cv::Mat(3, 3, CV_32F, cv::Scalar(1.0f)),
                                         cv::Mat(3, 3, CV_32F, cv::Scalar(0.0f)));
  EXPECT_EQ(s.gt_pixels, 0);
  EXPECT_EQ(s.density, 0.0);
}

}  // namespace
}  // namespace sg::eval
