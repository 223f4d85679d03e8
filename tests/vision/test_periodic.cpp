#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <hwy/targets.h>

#include <opencv2/core.hpp>

#include "sg/vision/periodic.hpp"
#include "sg/vision/stereo_bm.hpp"
#include "sg/vision/stereo_fast.hpp"
#include "synthetic.hpp"

namespace sg::vision {
namespace {

/// Diagonal stripes repeating every `period` px along the row (a sine, 100 grey levels either
/// side of 128), sampled at column x + shift.
cv::Mat stripes(cv::Size size, double period, double shift, double noise, uint64_t seed) {
  cv::Mat img(size, CV_8U);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      img.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(
          128.0 + 100.0 * std::sin(2.0 * CV_PI * (x + shift + 0.8 * y) / period));
  if (noise > 0) {
    cv::Mat n(size, CV_16S);
    cv::RNG(seed).fill(n, cv::RNG::NORMAL, 0, noise);
    cv::Mat sum;
    cv::add(img, n, sum, cv::noArray(), CV_16S);
    sum.convertTo(img, CV_8U);
  }
  return img;
}

double marked_share(const cv::Mat& mask, cv::Rect roi) {
  return static_cast<double>(cv::countNonZero(mask(roi))) / roi.area();
}

core::BmParams with_check() {
  core::BmParams p;  // the default ratio
  p.num_disparities = 64;
  EXPECT_GT(p.periodic_ratio, 0.0);
  return p;
}

// The cause: a striped wall 4.77 px away repeats every 7.8 px. At whole-pixel disparities the
// aliases 4.77 + 7.8 k land nearer a whole pixel than the true one, so the matcher prefers them
// and neither the uniqueness ratio nor the left-right check objects (the seed 1111 wall). With
// the check, no wrong match is left.
TEST(PeriodicTexture, WholePeriodAliasesAreMatchedWithoutTheCheckAndDroppedWithIt) {
  const cv::Size size(320, 240);
  const double truth = 4.77, period = 7.8;
  const cv::Mat left = stripes(size, period, 0.0, 2.5, 1);
  const cv::Mat right = stripes(size, period, truth, 2.5, 2);
  core::BmParams p = with_check();
  cv::Mat disp(size, CV_32F);
  match_fast_rows(left, right, p, disp, cv::Range::all());
  filter_speckles(disp, p);
  const cv::Rect inner(p.num_disparities, 8, size.width - p.num_disparities - 8, size.height - 16);
  const auto wrong = [&](const cv::Mat& d) {
    int n = 0;
    for (int y = inner.y; y < inner.br().y; ++y)
      for (int x = inner.x; x < inner.br().x; ++x) {
        const float v = d.at<float>(y, x);
        n += v >= 0 && std::abs(v - truth) > 2.0;
      }
    return n;
  };
  const int before = wrong(disp);
  EXPECT_GT(before, inner.area() / 5);  // the matcher alone is fooled on much of the wall
  disp.setTo(-1.0f, periodic_mask(left, p));
  EXPECT_EQ(wrong(disp), 0);
}

// Every period from 3 to 20 px is marked (a smooth sine of a longer period changes so little
// from one pixel to the next that a sub-pixel offset costs the true match little either, and
// the noise decides); a period longer than the range is not ambiguous for the matcher (one copy
// in reach) and is not marked.
TEST(PeriodicTexture, MarksPeriodsInsideTheRangeOnly) {
  const cv::Size size(320, 120);
  const core::BmParams p = with_check();
  const cv::Rect inner(p.num_disparities + 8, 8, size.width - p.num_disparities - 16,
                       size.height - 16);
  for (double period : {3.3, 5.0, 7.8, 12.5, 20.0}) {
    const cv::Mat mask = periodic_mask(stripes(size, period, 0.0, 2.0, 3), p);
    EXPECT_GT(marked_share(mask, inner), 0.95) << "period " << period;
  }
  const cv::Mat far = periodic_mask(stripes(size, 100.0, 0.0, 2.0, 3), p);
  EXPECT_LT(marked_share(far, inner), 0.01);
}

// Textures that do not repeat keep their matches: white noise (every shift costs about the
// same), smooth random textures (the cost grows with the shift; blurred by 8 px, some of their
// blobs are spaced evenly enough to be marked, about 1 %), and a textureless wall with sensor
// noise.
TEST(PeriodicTexture, LeavesTexturesThatDoNotRepeatAlone) {
  const cv::Size size(320, 240);
  const core::BmParams p = with_check();
  const cv::Rect all(0, 0, size.width, size.height);
  for (double sigma : {0.0, 1.2, 3.0, 8.0}) {
    cv::Mat tex = sigma > 0 ? test::texture(size, 7, sigma) : cv::Mat(size, CV_8U);
    if (sigma == 0) cv::RNG(7).fill(tex, cv::RNG::UNIFORM, 0, 256);
    EXPECT_LT(marked_share(periodic_mask(tex, p), all), 0.02) << "sigma " << sigma;
  }
  cv::Mat flat(size, CV_8U, cv::Scalar(120));
  cv::Mat noise(size, CV_16S);
  cv::RNG(8).fill(noise, cv::RNG::NORMAL, 0, 3.0);
  cv::add(flat, noise, flat, cv::noArray(), CV_8U);
  EXPECT_LT(marked_share(periodic_mask(flat, p), all), 0.01);
}

// Off (ratio 0) the map is untouched; on, only the striped half loses its matches.
TEST(PeriodicTexture, DropsOnlyTheRepeatingPartAndNothingWhenOff) {
  const cv::Size size(320, 160);
  cv::Mat left = test::texture(size, 11, 1.2);
  stripes({size.width / 2, size.height}, 9.0, 0.0, 2.0, 4)
      .copyTo(left(cv::Rect(size.width / 2, 0, size.width / 2, size.height)));
  const cv::Mat disp(size, CV_32F, cv::Scalar(6.0f));
  core::BmParams p = with_check();
  p.periodic_ratio = 0.0;
  cv::Mat off = disp.clone();
  off.setTo(-1.0f, periodic_mask(left, p));
  EXPECT_EQ(cv::countNonZero(off != disp), 0);
  p.periodic_ratio = core::BmParams{}.periodic_ratio;
  cv::Mat on = disp.clone();
  on.setTo(-1.0f, periodic_mask(left, p));
  const cv::Mat dropped = on < 0;
  EXPECT_LT(marked_share(dropped, cv::Rect(0, 0, size.width / 2 - 16, size.height)), 0.01);
  EXPECT_GT(marked_share(dropped, cv::Rect(size.width / 2 + 80, 8, size.width / 2 - 88,
                                           size.height - 16)),
            0.95);
}

// The kernel (every SIMD target this machine runs and this build compiled) equals the scalar
// reference pixel for pixel: over image widths that are no multiple of a cell or a vector, blocks
// of one to nine cells, ranges beyond half the width, both caps and two ratios, on a picture
// that is half stripes and half noise so that both verdicts occur.
TEST(PeriodicTexture, KernelEqualsTheScalarReferenceOnEveryTarget) {
  int checked = 0;
  for (const cv::Size size : {cv::Size(317, 123), cv::Size(640, 96)}) {
    cv::Mat left = test::texture(size, 21, 1.5);
    const int half = size.width / 2;
    stripes({size.width - half, size.height}, 7.3, 0.0, 2.0, 5)
        .copyTo(left(cv::Rect(half, 0, size.width - half, size.height)));
    for (const int block : {5, 11, 21, 35})
      for (const int range : {16, 64, 336})
        for (const int cap : {31, 63})
          for (const double ratio : {0.3, 0.6}) {
            core::BmParams p;
            p.block_size = block;
            p.num_disparities = range;
            p.prefilter_cap = cap;
            p.periodic_ratio = ratio;
            const cv::Mat expected = periodic_mask_reference(left, p);
            const std::string what = std::to_string(size.width) + " px, block " +
                                     std::to_string(block) + ", range " + std::to_string(range) +
                                     ", cap " + std::to_string(cap) + ", ratio " +
                                     std::to_string(ratio);
            const int marked = cv::countNonZero(expected);
            EXPECT_GT(marked, 0) << what;
            EXPECT_LT(marked, size.area()) << what;
            for (const int64_t target : hwy::SupportedAndGeneratedTargets()) {
              hwy::SetSupportedTargetsForTest(target);
              const cv::Mat mask = periodic_mask(left, p);
              EXPECT_EQ(cv::countNonZero(mask != expected), 0)
                  << what << ", target " << hwy::TargetName(target);
              ++checked;
            }
            hwy::SetSupportedTargetsForTest(0);
          }
  }
  EXPECT_GE(checked, 2 * 4 * 3 * 2 * 2);
}

}  // namespace
}  // namespace sg::vision
