#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "sg/core/error.hpp"
#include "sg/vision/motion_parallax.hpp"

namespace sg::vision {
namespace {

/// The backward flow of a forward field F(x, y) = (k (x - fx) + u, k (y - fy)): B = -F.
cv::Mat backward(cv::Size size, double k, cv::Point2d foe, double u) {
  cv::Mat flow(size, CV_32FC2);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      flow.at<cv::Vec2f>(y, x) = cv::Vec2f(static_cast<float>(-(k * (x - foe.x) + u)),
                                           static_cast<float>(-(k * (y - foe.y))));
  return flow;
}

TEST(MotionParallax, AnExpansionOffCentreDiverges) {
  // Expanding by 2 % a frame about a point right of and above the centre, at 30 Hz: the halves
  // differ by k w / 2 = 0.02 * 160 / 2 px a frame, whatever the focus.
  const cv::Size size(160, 120);
  const double dt = 1.0 / 30.0;
  for (const cv::Point2d foe : {cv::Point2d(120, 40), cv::Point2d(30, 90), cv::Point2d(80, 60)}) {
    const ParallaxScore s = motion_parallax(backward(size, 0.02, foe, 0.0), dt);
    EXPECT_NEAR(s.divergence_px_s, 0.02 * 80 / dt, 1e-3) << foe;
    EXPECT_EQ(s.pixels, size.area());
  }
  // The focus right of the centre: the left half's flow is the larger (the obstacle is there).
  const ParallaxScore s = motion_parallax(backward(size, 0.02, {120, 40}, 0.0), dt);
  EXPECT_GT(std::abs(s.left_px_s), std::abs(s.right_px_s));
}

TEST(MotionParallax, AUniformTranslationOrARecessionDoesNot) {
  const cv::Size size(160, 120);
  const double dt = 1.0 / 30.0;
  const ParallaxScore slide = motion_parallax(backward(size, 0.0, {80, 60}, 5.0), dt);
  EXPECT_NEAR(slide.divergence_px_s, 0.0, 1e-6);
  EXPECT_NEAR(slide.left_px_s, 150.0, 1e-3);  // 5 px a frame at 30 Hz
  const ParallaxScore away = motion_parallax(backward(size, -0.02, {50, 60}, 3.0), dt);
  EXPECT_LT(away.divergence_px_s, 0.0);
}

TEST(MotionParallax, LeavesOutUnknownFlowAndRejectsBadInput) {
  cv::Mat flow = backward({40, 10}, 0.05, {20, 5}, 0.0);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int y = 0; y < 10; ++y) flow.at<cv::Vec2f>(y, 0) = cv::Vec2f(nan, 0.0f);
  const ParallaxScore s = motion_parallax(flow, 0.1);
  EXPECT_EQ(s.pixels, 390);
  EXPECT_TRUE(std::isfinite(s.divergence_px_s));
  EXPECT_THROW(motion_parallax(cv::Mat(4, 4, CV_32FC1), 0.1), core::InputError);
  EXPECT_THROW(motion_parallax(flow, 0.0), core::InputError);
  EXPECT_THROW(motion_parallax(cv::Mat(), 0.1), core::InputError);
}

}  // namespace
}  // namespace sg::vision
