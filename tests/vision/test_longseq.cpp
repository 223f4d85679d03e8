#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "sg/core/error.hpp"
#include "sg/vision/longseq.hpp"

namespace sg::vision {
namespace {

std::vector<std::uint8_t> bits(const char* text) {
  std::vector<std::uint8_t> out;
  for (const char* c = text; *c; ++c) out.push_back(*c == '1' ? 1 : 0);
  return out;
}

TEST(LongSeq, ReproducesTheThesisWorkedExample) {
  // Thesis 3.2.3: [110001001] -> [113331221], and the disparity lies in the run of three zeros.
  const std::vector<std::uint8_t> bad = bits("110001001");
  std::vector<int> lengths(bad.size());
  good_run_lengths(bad.data(), static_cast<int>(bad.size()), lengths.data());
  EXPECT_EQ(lengths, (std::vector<int>{1, 1, 3, 3, 3, 1, 2, 2, 1}));
  const int d = longest_good_run(bad.data(), static_cast<int>(bad.size()));
  EXPECT_GE(d, 2);
  EXPECT_LE(d, 4);
  EXPECT_EQ(d, 3);  // the run's middle
}

TEST(LongSeq, LongestRunEdgeCases) {
  auto run = [](const char* text) {
    const std::vector<std::uint8_t> b = bits(text);
    return longest_good_run(b.data(), static_cast<int>(b.size()));
  };
  EXPECT_EQ(run("1111"), -1);   // nothing good: unmatched
  EXPECT_EQ(run("0000"), 1);    // one run over everything: its middle, rounded down
  EXPECT_EQ(run("0110"), 0);    // a tie: the first run
  EXPECT_EQ(run("1001000"), 5);  // the later, longer run wins
  std::vector<int> lengths(4);
  const std::vector<std::uint8_t> b = bits("0000");
  good_run_lengths(b.data(), 4, lengths.data());
  EXPECT_EQ(lengths, (std::vector<int>{4, 4, 4, 4}));
}

/// A left image of smooth texture and its right view of a fronto-parallel plane at disparity
/// `d`: right(x) = left(x + d).
void shifted_pair(int d, cv::Mat& left, cv::Mat& right) {
  cv::Mat noise(120, 200, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(noise, left, cv::Size(0, 0), 1.2);
  cv::normalize(left, left, 0, 255, cv::NORM_MINMAX);
  right.create(left.size(), CV_8UC1);
  for (int y = 0; y < left.rows; ++y)
    for (int x = 0; x < left.cols; ++x)
      right.at<std::uint8_t>(y, x) = left.at<std::uint8_t>(y, std::min(left.cols - 1, x + d));
}

TEST(LongSeq, RecoversTheDisparityOfAShiftedTexture) {
  cv::Mat left, right;
  shifted_pair(11, left, right);
  int too_near[2] = {0, 0};
  for (const bool both : {false, true}) {
    LongSeqParams p;
    p.num_disparities = 32;
    p.both_ways = both;
    cv::Mat disp;
    longseq_disparity(left, right, p, disp);
    ASSERT_EQ(disp.type(), CV_32FC1);
    int valid = 0, right_value = 0, searched = 0;
    for (int y = 0; y < disp.rows; ++y)
      for (int x = 40; x < disp.cols - 40; ++x) {  // where every disparity can be searched
        ++searched;
        const float v = disp.at<float>(y, x);
        if (v < 0) continue;
        ++valid;
        right_value += std::abs(v - 11.0f) <= 1.0f ? 1 : 0;
        too_near[both] += v > 12.0f ? 1 : 0;
      }
    EXPECT_GT(valid, searched * 8 / 10) << "both ways " << both;
    // The first longest run wins a tie, so a few pixels take an accidental run of equal length.
    EXPECT_GT(right_value, valid * (both ? 90 : 95) / 100) << "both ways " << both;
    // The border where the search leaves the image is unmatched.
    EXPECT_LT(disp.at<float>(10, 2), 0.0f);
  }
  // Matching both ways keeps the smaller disparity: fewer pixels seen nearer than they are.
  EXPECT_LT(too_near[1], too_near[0]);
}

TEST(LongSeq, RunningSumsEqualTheReferenceAndRowTilesTheWholeImage) {
  cv::RNG rng(21);
  for (int trial = 0; trial < 12; ++trial) {
    const cv::Size size(rng.uniform(40, 160), rng.uniform(1, 30));
    cv::Mat left(size, CV_8UC1), right;
    rng.fill(left, cv::RNG::UNIFORM, 0, 256);
    cv::GaussianBlur(left, left, cv::Size(0, 0), rng.uniform(0.5, 2.0));
    const int shift = rng.uniform(0, 12);
    right = cv::Mat(size, CV_8UC1);
    for (int y = 0; y < size.height; ++y)
      for (int x = 0; x < size.width; ++x)
        right.at<std::uint8_t>(y, x) = cv::saturate_cast<std::uint8_t>(
            left.at<std::uint8_t>(y, std::min(size.width - 1, x + shift)) + rng.uniform(-4, 5));
    LongSeqParams p;
    p.num_disparities = rng.uniform(shift + 2, 24);  // the true disparity within the range
    p.window_px = 2 * rng.uniform(0, 4) + 1;
    // (Up to 10: with more, every disparity of a blurred texture can match, and such pixels are
    // unmatched.)
    p.cost_max = rng.uniform(2.0, 10.0);
    p.best_max = rng.uniform(p.cost_max / 2, p.cost_max);
    p.both_ways = trial % 2 == 0;
    cv::Mat fast, reference;
    longseq_disparity(left, right, p, fast);
    longseq_disparity_reference(left, right, p, reference);
    ASSERT_EQ(cv::norm(fast, reference, cv::NORM_INF), 0.0) << "trial " << trial;
    EXPECT_GT(cv::countNonZero(reference >= 0.0f), 0) << "trial " << trial;
    cv::Mat tiled(size, CV_32FC1, cv::Scalar(-7.0f));
    const int cut = size.height / 2;
    longseq_disparity_rows(left, right, p, tiled, cv::Range(cut, size.height));
    longseq_disparity_rows(left, right, p, tiled, cv::Range(0, cut));
    EXPECT_EQ(cv::norm(tiled, reference, cv::NORM_INF), 0.0) << "trial " << trial;
  }
}

TEST(LongSeq, AFlatImageHasNoLongestRunToTrustAndIsUnmatched) {
  // Every disparity matches a uniform image equally: one run over the whole range, whose middle
  // the thesis' rule would take (a near point on every patch of sky). Such pixels are unmatched,
  // in the reference and the fast path; a textured row beside them still matches.
  cv::Mat left(20, 100, CV_8UC1, cv::Scalar(90));
  for (int x = 0; x < 100; ++x) left.at<std::uint8_t>(5, x) = static_cast<std::uint8_t>((x * 37) % 200);
  cv::Mat right = left.clone();
  LongSeqParams p;
  p.num_disparities = 16;
  p.both_ways = false;
  cv::Mat disp, reference;
  longseq_disparity(left, right, p, disp);
  longseq_disparity_reference(left, right, p, reference);
  EXPECT_EQ(disp.at<float>(10, 50), -1.0f);
  EXPECT_EQ(reference.at<float>(10, 50), -1.0f);
  EXPECT_EQ(disp.at<float>(5, 50), 0.0f);
  EXPECT_EQ(cv::norm(disp, reference, cv::NORM_INF), 0.0);
}

TEST(LongSeq, RejectsBadInputAndParametersByName) {
  cv::Mat a(10, 40, CV_8UC1, cv::Scalar(0)), b(10, 41, CV_8UC1, cv::Scalar(0)), disp;
  EXPECT_THROW(longseq_disparity(a, b, LongSeqParams{}, disp), core::InputError);
  cv::Mat c(10, 40, CV_32FC1, cv::Scalar(0));
  EXPECT_THROW(longseq_disparity(a, c, LongSeqParams{}, disp), core::InputError);
  LongSeqParams p;
  p.window_px = 4;
  p.best_max = 300;
  const std::vector<std::string> problems = validate(p);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0], "longseq.window_px=4: must be odd, in 1..63");
  EXPECT_NE(problems[1].find("longseq.best_max=300"), std::string::npos);
  EXPECT_THROW(longseq_disparity(a, a, p, disp), core::InputError);
  EXPECT_TRUE(validate(LongSeqParams{}).empty());
}

}  // namespace
}  // namespace sg::vision
