// The simulator's motion blur (motion_blur, one fused pass) against its reference
// (motion_blur_reference, one cv::remap per sample): equal byte for byte.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "sg/sim/motion_blur.hpp"

namespace sg::sim {
namespace {

/// A textured image, and a flow with large and sub-pixel parts (smooth, or jittered pixel by
/// pixel), points far outside the image near its borders (BORDER_REPLICATE), and a few very long
/// vectors (many samples).
struct BlurCase {
  cv::Mat gray, flow, noise;
  double share = 0.0;
};

BlurCase random_case(int width, int height, std::uint64_t seed, bool with_noise) {
  cv::RNG rng(seed);
  BlurCase c;
  c.gray.create(height, width, CV_8UC1);
  rng.fill(c.gray, cv::RNG::UNIFORM, 0, 256);
  c.flow.create(height, width, CV_32FC2);
  const double scale = rng.uniform(0.5, 25.0);
  // Every other case smooth: runs of pixels whose samples fall on consecutive pixels.
  const double jitter = seed % 2 == 0 ? 0.3 : 0.0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const double u = scale * (std::sin(0.03 * x + 0.5 * seed) + rng.uniform(-jitter, jitter));
      const double v = scale * (std::cos(0.05 * y) + rng.uniform(-jitter, jitter));
      c.flow.at<cv::Vec2f>(y, x) = cv::Vec2f(static_cast<float>(u), static_cast<float>(v));
    }
  if (rng.uniform(0, 2) == 0) c.flow.at<cv::Vec2f>(height / 2, 1) = cv::Vec2f(-300.0f, 41.5f);
  // Beyond the int range once scaled to 1/32 px, where cv::remap's rounding wraps around.
  if (rng.uniform(0, 3) == 0) c.flow.at<cv::Vec2f>(1, width / 3) = cv::Vec2f(3e9f, -2e9f);
  if (with_noise) {
    c.noise.create(height, width, CV_32FC1);
    rng.fill(c.noise, cv::RNG::NORMAL, 0.0, 3.0);
  }
  c.share = rng.uniform(0.05, 1.0);
  return c;
}

TEST(MotionBlur, EveryTargetEqualsOneRemapPerSampleByteForByte) {
  constexpr int kCases = 24;
  std::vector<BlurCase> cases;
  std::vector<cv::Mat> references;
  int blurred = 0;
  for (int i = 0; i < kCases; ++i) {
    // Widths of no whole number of vectors, so that the scalar tail runs too.
    const int width = 37 + 29 * (i % 5), height = 23 + 17 * (i % 4);
    cases.push_back(random_case(width, height, 100 + i, i % 3 != 0));
    references.push_back(cases.back().gray.clone());
    const BlurCase& c = cases.back();
    motion_blur_reference(references.back(), c.flow, c.share, c.noise);
    blurred += cv::countNonZero(references.back() != c.gray) > width * height / 2 ? 1 : 0;
  }
  EXPECT_EQ(blurred, kCases) << "every case must change most pixels, or it tests nothing";
  for (std::int64_t target : hwy::SupportedAndGeneratedTargets()) {
    hwy::SetSupportedTargetsForTest(target);
    for (int i = 0; i < kCases; ++i) {
      const BlurCase& c = cases[static_cast<std::size_t>(i)];
      cv::Mat fast = c.gray.clone();
      motion_blur(fast, c.flow, c.share, c.noise);
      ASSERT_EQ(fast.size(), c.gray.size());
      ASSERT_EQ(fast.type(), CV_8UC1);
      EXPECT_EQ(cv::countNonZero(fast != references[static_cast<std::size_t>(i)]), 0)
          << hwy::TargetName(target) << ": case " << i << ", " << c.gray.cols << "x" << c.gray.rows
          << ", share " << c.share;
    }
  }
  hwy::SetSupportedTargetsForTest(0);
}

TEST(MotionBlur, ZeroFlowKeepsTheImageAndAddsTheNoise) {
  cv::Mat gray(20, 30, CV_8UC1), noise(20, 30, CV_32FC1, cv::Scalar(2.4f));
  cv::randu(gray, 0, 250);
  cv::Mat flow(20, 30, CV_32FC2, cv::Scalar(0.0f, 0.0f)), out = gray.clone();
  motion_blur(out, flow, 0.5, noise);
  cv::Mat expected;
  gray.convertTo(expected, CV_8UC1, 1.0, 2.4);
  EXPECT_EQ(cv::countNonZero(out != expected), 0);
}

}  // namespace
}  // namespace sg::sim
