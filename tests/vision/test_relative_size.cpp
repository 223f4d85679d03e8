#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "sg/core/error.hpp"
#include "sg/vision/relative_size.hpp"
#include "synthetic.hpp"

namespace sg::vision {
namespace {

using test::texture;

/// `image` scaled by s about `centre` (and moved so that centre lands on `to`).
cv::Mat scaled(const cv::Mat& image, double s, cv::Point2f centre, cv::Point2f to) {
  const cv::Matx23d a(s, 0.0, to.x - s * centre.x, 0.0, s, to.y - s * centre.y);
  cv::Mat out;
  cv::warpAffine(image, out, a, image.size(), cv::INTER_CUBIC, cv::BORDER_REFLECT);
  return out;
}

TEST(RelativeSize, RecoversAKnownScaleChangeOfATexturedPatchWithin2Percent) {
  const cv::Mat prev = texture({320, 240}, 3, 2.0);
  const RelativeSizeParams p;
  for (const double s : {1.0, 1.04, 1.1, 1.2, 1.35, 0.9}) {
    const cv::Point2f from(150.0f, 110.0f), to(162.0f, 104.0f);
    const cv::Mat cur = scaled(prev, s, from, to);
    double error = 0.0;
    const double found = patch_scale(prev, cur, from, to, 36.0, p, &error);
    EXPECT_NEAR(found / s, 1.0, 0.02) << "scale " << s;
    EXPECT_LT(error, 5.0) << "scale " << s;
  }
  // A template leaving the image has no scale.
  EXPECT_EQ(patch_scale(prev, prev, {5.0f, 5.0f}, {5.0f, 5.0f}, 36.0, p), 0.0);
}

TEST(RelativeSize, CoarseToFineFindsTheScaleOfTheFullSearch) {
  const cv::Mat prev = texture({320, 240}, 7, 2.0);
  const RelativeSizeParams p;
  int trials = 0;
  cv::RNG rng(11);
  for (int k = 0; k < 40; ++k) {
    const double s = rng.uniform(0.85, 1.4);
    const cv::Point2f from(rng.uniform(80.0f, 240.0f), rng.uniform(70.0f, 170.0f));
    const cv::Point2f to = from + cv::Point2f(rng.uniform(-8.0f, 8.0f), rng.uniform(-8.0f, 8.0f));
    const cv::Mat cur = scaled(prev, s, from, to);
    double full_error = 0.0, coarse_error = 0.0;
    const double full = patch_scale(prev, cur, from, to, 30.0, p, &full_error);
    const double coarse = patch_scale(prev, cur, from, to, 30.0, p, &coarse_error, 4);
    if (full == 0.0) continue;
    ++trials;
    EXPECT_DOUBLE_EQ(coarse, full) << "scale " << s;
    EXPECT_DOUBLE_EQ(coarse_error, full_error) << "scale " << s;
  }
  EXPECT_GT(trials, 30);
}

TEST(RelativeSize, AnExpandingTexturedSquareIsAClusterTheStaticBackgroundIsNot) {
  // A static background and, in front of it, a textured square that grows by 12 %.
  const auto frame = test::square_before_background;
  const cv::Mat prev = frame(140.0), cur = frame(140.0 * 1.12);
  const std::vector<ExpandingFeature> found = expanding_features(prev, cur, RelativeSizeParams{});
  const cv::Rect square(240 - 79, 180 - 79, 158, 158);
  int in_cluster = 0, inside = 0;
  for (const ExpandingFeature& f : found) {
    if (f.cluster < 0) continue;
    ++in_cluster;
    inside += square.contains(cv::Point(f.at)) ? 1 : 0;
    EXPECT_NEAR(f.scale, 1.12, 0.05);
  }
  EXPECT_GE(in_cluster, 5);
  EXPECT_GE(inside, in_cluster * 9 / 10);
  // Nothing expands between two equal frames.
  for (const ExpandingFeature& f : expanding_features(prev, prev, RelativeSizeParams{}))
    EXPECT_LT(f.cluster, 0);
}

TEST(RelativeSize, RejectsBadInputAndParametersByName) {
  RelativeSizeParams p;
  p.s_min = 0.9;
  const std::vector<std::string> problems = validate(p);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0], "relative_size.s_min=0.9: must be > 1");
  const cv::Mat a(40, 40, CV_8UC1, cv::Scalar(0)), b(40, 41, CV_8UC1, cv::Scalar(0));
  EXPECT_THROW(expanding_features(a, b, RelativeSizeParams{}), core::InputError);
  EXPECT_THROW(expanding_features(a, a, p), core::InputError);
  EXPECT_TRUE(validate(RelativeSizeParams{}).empty());
}

}  // namespace
}  // namespace sg::vision
