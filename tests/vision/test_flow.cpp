#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "sg/core/error.hpp"
#include "sg/vision/flow.hpp"

namespace sg::vision {
namespace {

constexpr FlowMethod kAllMethods[] = {FlowMethod::kDisUltrafast, FlowMethod::kDisFast,
                                      FlowMethod::kDisMedium, FlowMethod::kFarneback};

/// Smooth random texture (float, 0..255), fixed seed.
cv::Mat texture(cv::Size size, uint64_t seed) {
  cv::Mat noise(size, CV_32F);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0.0, 255.0);
  cv::Mat smooth;
  cv::GaussianBlur(noise, smooth, cv::Size(0, 0), 1.5);
  cv::normalize(smooth, smooth, 0, 255, cv::NORM_MINMAX);
  return smooth;
}

/// previous = texture; current(x, y) = previous(x - dx, y - dy): the scene moved by (dx, dy), so
/// the backward flow (current -> previous) is (-dx, -dy).
void shifted_pair(cv::Size size, double dx, double dy, cv::Mat& current, cv::Mat& previous,
                  uint64_t seed = 7) {
  const cv::Mat base = texture(size, seed);
  const cv::Matx23d shift(1, 0, dx, 0, 1, dy);
  cv::Mat moved;
  cv::warpAffine(base, moved, shift, size, cv::INTER_CUBIC, cv::BORDER_REFLECT);
  base.convertTo(previous, CV_8U);
  moved.convertTo(current, CV_8U);
}

cv::Scalar interior_mean(const cv::Mat& flow, int margin) {
  return cv::mean(flow(cv::Rect(margin, margin, flow.cols - 2 * margin, flow.rows - 2 * margin)));
}

TEST(FlowParams, NamesRoundTrip) {
  for (FlowMethod m : kAllMethods) EXPECT_EQ(parse_flow_method(to_string(m)), m);
  EXPECT_STREQ(to_string(FlowMethod::kDisUltrafast), "dis-ultrafast");
  EXPECT_STREQ(to_string(FlowMethod::kFarneback), "farneback");
  EXPECT_THROW(parse_flow_method("dis"), core::InputError);
  EXPECT_EQ(FlowParams{}.method, FlowMethod::kDisUltrafast);
}

TEST(FlowParams, ValidateNamesTheField) {
  EXPECT_TRUE(validate(FlowParams{}).empty());
  FlowParams p;
  p.method = FlowMethod::kFarneback;
  p.fb_poly_n = 6;
  p.fb_pyr_scale = 1.5;
  const auto problems = validate(p);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_NE(problems[0].find("flow.fb_pyr_scale=1.5"), std::string::npos);
  EXPECT_NE(problems[1].find("flow.fb_poly_n=6"), std::string::npos);
}

TEST(ComputeFlow, RejectsBadInputs) {
  FlowParams p;
  cv::Mat flow;
  const cv::Mat a(31, 41, CV_8U, cv::Scalar(3)), b(33, 41, CV_8U, cv::Scalar(3));
  EXPECT_THROW(compute_flow(a, b, p, flow), core::InputError);
  EXPECT_THROW(compute_flow(a, cv::Mat(31, 41, CV_8UC3), p, flow), core::InputError);
  EXPECT_THROW(compute_flow(cv::Mat(), a, p, flow), core::InputError);
}

// Sign convention: the scene moves by (+dx, +dy) from previous to current, so each pixel of the
// current image was at p - (dx, dy): backward flow is (-dx, -dy).
TEST(ComputeFlow, BackwardFlowOfASubpixelShift) {
  const double dx = 2.3, dy = -1.6;
  cv::Mat current, previous;
  shifted_pair({203, 151}, dx, dy, current, previous);
  for (FlowMethod m : kAllMethods) {
    FlowParams p;
    p.method = m;
    cv::Mat flow;
    compute_flow(current, previous, p, flow);
    ASSERT_EQ(flow.type(), CV_32FC2) << to_string(m);
    ASSERT_EQ(flow.size(), current.size()) << to_string(m);
    const cv::Scalar mean = interior_mean(flow, 16);
    EXPECT_NEAR(mean[0], -dx, 0.1) << to_string(m);
    EXPECT_NEAR(mean[1], -dy, 0.1) << to_string(m);
  }
}

TEST(ComputeFlow, EstimatorMatchesFreeFunctionAcrossFrames) {
  cv::Mat c1, p1, c2, p2;
  shifted_pair({121, 97}, 1.25, 0.5, c1, p1, 3);
  shifted_pair({121, 97}, -0.75, 1.5, c2, p2, 4);
  for (FlowMethod m : kAllMethods) {
    FlowParams p;
    p.method = m;
    FlowEstimator est(p);
    cv::Mat a1, a2, b1, b2;
    est.compute(c1, p1, a1);
    est.compute(c2, p2, a2);  // reused buffers must not leak state between frames
    compute_flow(c1, p1, p, b1);
    compute_flow(c2, p2, p, b2);
    EXPECT_EQ(cv::norm(a1, b1, cv::NORM_INF), 0.0) << to_string(m);
    EXPECT_EQ(cv::norm(a2, b2, cv::NORM_INF), 0.0) << to_string(m);
  }
}

// DIS cuts its parallel loops into a fixed number of stripes and Farneback's loops are row-wise, so
// the flow must not change with the thread count (meaningful only with >= 2 threads by default).
TEST(ComputeFlow, IndependentOfThreadCount) {
  cv::Mat current, previous;
  shifted_pair({641, 481}, 3.4, 1.2, current, previous, 11);
  const int threads = cv::getNumThreads();
  for (FlowMethod m : kAllMethods) {
    FlowParams p;
    p.method = m;
    cv::Mat many, one;
    cv::setNumThreads(threads);
    compute_flow(current, previous, p, many);
    cv::setNumThreads(1);
    compute_flow(current, previous, p, one);
    cv::setNumThreads(threads);
    EXPECT_EQ(cv::norm(many, one, cv::NORM_INF), 0.0) << to_string(m);
  }
  EXPECT_EQ(cv::getNumThreads(), threads);
}

// Tiles see only their rows plus a halo; pyramids make them differ near the cuts, so the
// tolerance is on the mean: every tile must still find the shift.
TEST(ComputeFlow, TilesStitchCloseToTheWholeImage) {
  const double dx = -1.7, dy = 0.9;
  cv::Mat current, previous;
  shifted_pair({243, 301}, dx, dy, current, previous, 5);
  FlowParams p;
  p.method = FlowMethod::kDisFast;
  cv::Mat whole, tiled;
  compute_flow(current, previous, p, whole);
  const int cuts[] = {0, 97, 211, 301};
  for (int t = 0; t < 3; ++t) compute_flow_rows(current, previous, p, tiled, {cuts[t], cuts[t + 1]});
  ASSERT_EQ(tiled.size(), whole.size());
  const cv::Scalar mean = interior_mean(tiled, 16);
  EXPECT_NEAR(mean[0], -dx, 0.1);
  EXPECT_NEAR(mean[1], -dy, 0.1);
  cv::Mat diff;
  cv::absdiff(whole, tiled, diff);
  const cv::Scalar mad = interior_mean(diff, 16);
  EXPECT_LT(mad[0] + mad[1], 0.1);
  // Whole-image range reads everything: identical to compute_flow.
  cv::Mat all;
  compute_flow_rows(current, previous, p, all, cv::Range::all());
  EXPECT_EQ(cv::norm(all, whole, cv::NORM_INF), 0.0);
  EXPECT_EQ(flow_input_rows({97, 211}, p, 301), cv::Range(97 - 48, 211 + 48));
  EXPECT_EQ(flow_input_rows({0, 40}, p, 301), cv::Range(0, 88));
}

}  // namespace
}  // namespace sg::vision
