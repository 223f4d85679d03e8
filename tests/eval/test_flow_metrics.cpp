#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>

#include "sg/core/error.hpp"
#include "sg/eval/flow_metrics.hpp"

namespace sg::eval {
namespace {

TEST(FlowAccuracy, HandComputedErrors) {
  cv::Mat gt(3, 5, CV_32FC2, cv::Scalar(1.0, -2.0));
  cv::Mat flow = gt.clone();
  flow.at<cv::Vec2f>(0, 0) = cv::Vec2f(4.0f, 2.0f);  // error (3, 4): 5 px, bad
  flow.at<cv::Vec2f>(1, 1) = cv::Vec2f(1.0f, 1.0f);  // error 3 px exactly: not bad (> 3)
  gt.at<cv::Vec2f>(2, 4) = cv::Vec2f(1e9f, 0.0f);    // unknown: skipped
  flow.at<cv::Vec2f>(2, 4) = cv::Vec2f(100.0f, 100.0f);
  gt.at<cv::Vec2f>(2, 3) = cv::Vec2f(NAN, 0.0f);     // unknown too
  const FlowAccuracy a = flow_accuracy(flow, gt);
  EXPECT_EQ(a.valid_pixels, 13);
  EXPECT_DOUBLE_EQ(a.epe, 8.0 / 13.0);
  EXPECT_DOUBLE_EQ(a.bad3_percent, 100.0 / 13.0);
}

TEST(FlowAccuracy, NonFiniteEstimateCountsAsZeroFlow) {
  const cv::Mat gt(1, 3, CV_32FC2, cv::Scalar(3.0, 4.0));
  cv::Mat flow = gt.clone();
  flow.at<cv::Vec2f>(0, 1) = cv::Vec2f(NAN, 4.0f);
  const FlowAccuracy a = flow_accuracy(flow, gt);
  EXPECT_DOUBLE_EQ(a.epe, 5.0 / 3.0);
  EXPECT_EQ(a.valid_pixels, 3);
}

TEST(FlowAccuracy, NoValidPixels) {
  const cv::Mat gt(2, 3, CV_32FC2, cv::Scalar(2e9, 0.0));
  const FlowAccuracy a = flow_accuracy(cv::Mat::zeros(2, 3, CV_32FC2), gt);
  EXPECT_EQ(a.valid_pixels, 0);
  EXPECT_EQ(a.epe, 0.0);
}

TEST(FlowAccuracy, RejectsMismatches) {
  const cv::Mat gt(3, 5, CV_32FC2, cv::Scalar(0, 0));
  EXPECT_THROW(flow_accuracy(cv::Mat::zeros(5, 3, CV_32FC2), gt), core::InputError);
  EXPECT_THROW(flow_accuracy(cv::Mat::zeros(3, 5, CV_32FC1), gt), core::InputError);
}

}  // namespace
}  // namespace sg::eval
