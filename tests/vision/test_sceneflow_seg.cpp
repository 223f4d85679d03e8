#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "sg/core/error.hpp"
#include "sg/vision/sceneflow_seg.hpp"

namespace sg::vision {
namespace {

/// The least E over every labelling of a tiny image, by enumeration.
double brute_force_minimum(const cv::Mat& image, const cv::Mat& xi, const SceneFlowSegParams& p) {
  const int n = image.rows * image.cols;
  double best = std::numeric_limits<double>::infinity();
  cv::Mat labels(image.size(), CV_8UC1);
  for (int bits = 0; bits < (1 << n); ++bits) {
    for (int i = 0; i < n; ++i)
      labels.at<std::uint8_t>(i / image.cols, i % image.cols) = (bits >> i) & 1;
    best = std::min(best, segmentation_energy(image, xi, p, labels));
  }
  return best;
}

TEST(SceneFlowSeg, TheGraphCutEqualsABruteForceMinimumCut) {
  cv::RNG rng(11);
  int mixed = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const cv::Size size(rng.uniform(1, 5), rng.uniform(1, 4));
    cv::Mat image(size, CV_8UC1), xi(size, CV_32FC1);
    rng.fill(image, cv::RNG::UNIFORM, 0, 256);
    rng.fill(xi, cv::RNG::UNIFORM, 0.0, 6.0);
    if (trial % 3 == 0) xi.at<float>(0, 0) = std::numeric_limits<float>::quiet_NaN();
    SceneFlowSegParams p;
    p.lambda = rng.uniform(0.0, 40.0);
    cv::Mat moving;
    double energy = 0.0;
    segment_moving(image, xi, p, moving, &energy);
    const double best = brute_force_minimum(image, xi, p);
    EXPECT_NEAR(segmentation_energy(image, xi, p, moving), best, 1e-9) << "trial " << trial;
    EXPECT_NEAR(energy, best, 1e-9) << "trial " << trial;
    const int count = cv::countNonZero(moving);
    mixed += count > 0 && count < size.area() ? 1 : 0;
  }
  EXPECT_GT(mixed, 10);  // the cuts are not all trivial
}

TEST(SceneFlowSeg, SmoothsALikelyBlobAndIgnoresIsolatedNoise) {
  // A moving square of high likelihood with one low pixel inside, and one high pixel outside.
  cv::Mat image(20, 20, CV_8UC1, cv::Scalar(100)), xi(20, 20, CV_32FC1, cv::Scalar(0.5));
  xi(cv::Rect(5, 5, 8, 8)).setTo(8.0);
  image(cv::Rect(5, 5, 8, 8)).setTo(180);
  xi.at<float>(8, 8) = 0.5;
  xi.at<float>(16, 3) = 8.0;
  cv::Mat moving;
  segment_moving(image, xi, SceneFlowSegParams{}, moving);
  EXPECT_EQ(moving.at<std::uint8_t>(8, 8), 255);  // filled in by the smoothness
  EXPECT_EQ(moving.at<std::uint8_t>(16, 3), 0);   // too small against its neighbours
  EXPECT_EQ(cv::countNonZero(moving), 64);
}

TEST(SceneFlowSeg, MotionLikelihoodIsSmallForStaticAndLargeForMoving) {
  core::Camera cam;
  // A wall at 5 m, static: same disparity, zero flow; then approaching by 0.5 m.
  const auto d5 = static_cast<float>(cam.disparity(5.0));
  const auto d45 = static_cast<float>(cam.disparity(4.5));
  cv::Mat prev(40, 40, CV_32FC1, cv::Scalar(d5)), flow(40, 40, CV_32FC2, cv::Scalar(0, 0));
  cv::Mat xi;
  motion_likelihood(prev, prev, flow, cam, SceneFlowSegParams{}, xi);
  EXPECT_NEAR(xi.at<float>(20, 20), 0.0f, 1e-4);
  const cv::Mat now(40, 40, CV_32FC1, cv::Scalar(d45));
  motion_likelihood(now, prev, flow, cam, SceneFlowSegParams{}, xi);
  // The disparity change 1.33 px against s_c 0.35 px: far outside chi-square's 95 %.
  EXPECT_GT(xi.at<float>(20, 20), 3.0f);
  // Invalid disparities and flows leaving the image give no likelihood.
  cv::Mat holes = now.clone();
  holes.at<float>(3, 3) = -1.0f;
  flow.at<cv::Vec2f>(5, 5) = cv::Vec2f(-100.0f, 0.0f);
  motion_likelihood(holes, prev, flow, cam, SceneFlowSegParams{}, xi);
  EXPECT_TRUE(std::isnan(xi.at<float>(3, 3)));
  EXPECT_TRUE(std::isnan(xi.at<float>(5, 5)));
}

TEST(SceneFlowSeg, RejectsBadInputAndParametersByName) {
  SceneFlowSegParams p;
  p.sigma_flow_px = -1.0;
  const std::vector<std::string> problems = validate(p);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0], "sceneflow_seg.sigma_flow_px=-1: must be > 0 (px)");
  cv::Mat image(4, 4, CV_8UC1, cv::Scalar(0)), xi(4, 5, CV_32FC1, cv::Scalar(0)), out;
  EXPECT_THROW(segment_moving(image, xi, SceneFlowSegParams{}, out), core::InputError);
  EXPECT_THROW(segment_moving(image, xi(cv::Rect(0, 0, 4, 4)).clone(), p, out), core::InputError);
  EXPECT_TRUE(validate(SceneFlowSegParams{}).empty());
}

}  // namespace
}  // namespace sg::vision
