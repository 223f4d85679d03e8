#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <vector>

#include "sg/core/error.hpp"
#include "sg/vision/order_stats.hpp"

namespace sg::vision {
namespace {

/// The value of rank k by a full sort: the reference of both selections.
float by_sort(std::vector<float> v, size_t k) {
  std::sort(v.begin(), v.end());
  return v[k];
}

/// Ranks worth checking in a sample of n: the ends, the middle and its neighbours, the quartiles.
std::vector<size_t> ranks(size_t n) {
  return {0, 1, n / 4, n / 2 - 1, n / 2, n / 2 + 1, 3 * n / 4, n - 2, n - 1};
}

// Large samples take the sampled bracket, small ones the reference: both must give the sorted
// rank's value (and adjacent_smallest the two ranks k - 1 and k), on continuous values, on a 1/16 px grid full of ties (a box's disparities), with
// negatives, sorted, reversed, and all equal.
TEST(KthSmallest, AgreesWithASortOnEveryKindOfSample) {
  cv::RNG rng(11);
  for (const size_t n : {size_t{1000}, size_t{4095}, size_t{4096}, size_t{10001}, size_t{200000}}) {
    std::vector<std::vector<float>> samples(6, std::vector<float>(n));
    for (size_t i = 0; i < n; ++i) {
      samples[0][i] = static_cast<float>(rng.gaussian(1.0) + 1.2);
      samples[1][i] = static_cast<float>(std::round((57.0 + rng.gaussian(0.4)) * 16) / 16);
      samples[2][i] = static_cast<float>(rng.uniform(-50.0, 50.0));
      samples[3][i] = static_cast<float>(i) * 0.5f;
      samples[4][i] = static_cast<float>(n - i);
      samples[5][i] = 3.25f;
    }
    for (size_t s = 0; s < samples.size(); ++s) {
      const std::vector<float>& v = samples[s];
      for (const size_t k : ranks(n)) {
        const float expected = by_sort(v, k);
        EXPECT_EQ(kth_smallest(v, k), expected) << "n " << n << " sample " << s << " k " << k;
        EXPECT_EQ(kth_smallest_reference(v, k), expected) << "n " << n << " sample " << s;
        if (k == 0) continue;
        const auto [lower, upper] = adjacent_smallest(v, k);
        EXPECT_EQ(lower, by_sort(v, k - 1)) << "n " << n << " sample " << s << " k " << k;
        EXPECT_EQ(upper, expected) << "n " << n << " sample " << s << " k " << k;
      }
    }
  }
}

// A sample whose every 1/1024th value (the ones the bracket is drawn from) is an outlier: the
// bracket misses rank k and the reference must answer.
TEST(KthSmallest, ABracketThatMissesFallsBackToTheReference) {
  const size_t n = 1024 * 64;
  std::vector<float> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = i % 64 == 0 ? 1000.0f : static_cast<float>(i % 7);
  for (const size_t k : ranks(n)) {
    EXPECT_EQ(kth_smallest(v, k), by_sort(v, k)) << k;
    if (k > 0) {
      EXPECT_EQ(adjacent_smallest(v, k).first, by_sort(v, k - 1)) << k;
    }
  }
}

TEST(KthSmallest, LeavesItsInputAsItWasAndRejectsARankOutOfRange) {
  std::vector<float> v(5000);
  for (size_t i = 0; i < v.size(); ++i) v[i] = static_cast<float>((i * 7919) % 5000);
  const std::vector<float> before = v;
  EXPECT_EQ(kth_smallest(v, 2500), 2500.0f);
  EXPECT_EQ(v, before);
  EXPECT_THROW(kth_smallest(v, v.size()), core::InputError);
  EXPECT_THROW(kth_smallest_reference({}, 0), core::InputError);
  EXPECT_THROW(median_of({}), core::InputError);
  EXPECT_THROW(adjacent_smallest(v, 0), core::InputError);
  EXPECT_THROW(adjacent_smallest(v, v.size()), core::InputError);
}

TEST(MedianOf, TheMiddleValueOrTheMeanOfTheTwoMiddleOnes) {
  EXPECT_DOUBLE_EQ(median_of({3.0f, 1.0f, 2.0f}), 2.0);
  EXPECT_DOUBLE_EQ(median_of({4.0f, 1.0f, 3.0f, 2.0f}), 2.5);
  cv::RNG rng(5);
  std::vector<float> big(100000);
  for (float& x : big) x = static_cast<float>(rng.uniform(0.0, 10.0));
  std::vector<float> sorted = big;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_DOUBLE_EQ(median_of(big), 0.5 * (static_cast<double>(sorted[49999]) + sorted[50000]));
  big.push_back(20.0f);
  std::sort(sorted.begin(), sorted.end());
  sorted.push_back(20.0f);
  std::sort(sorted.begin(), sorted.end());
  EXPECT_DOUBLE_EQ(median_of(big), sorted[50000]);
}

}  // namespace
}  // namespace sg::vision
