#include "sg/vision/order_stats.hpp"

#include <algorithm>
#include <memory>
#include <utility>

#include "sg/core/error.hpp"

namespace sg::vision {
namespace {

/// Below this many values a copy and std::nth_element cost less than the sample and the pass.
constexpr std::size_t kFastFrom = 4096;
/// The sample that brackets rank k, and the sample ranks on either side of k's: the rank of k's
/// value in a sample of 1024 has a standard deviation of at most 16, so 48 miss about once in
/// a thousand (and then the reference runs).
constexpr std::size_t kSample = 1024;
constexpr std::size_t kMargin = 48;

}  // namespace

float kth_smallest_reference(const std::vector<float>& v, std::size_t k) {
  if (k >= v.size()) throw core::InputError("kth_smallest: rank out of range");
  std::vector<float> copy = v;
  std::nth_element(copy.begin(), copy.begin() + static_cast<std::ptrdiff_t>(k), copy.end());
  return copy[k];
}

namespace {

/// One pass of the sampled bracket around rank k: the count below lo, at lo and at hi, and the
/// values strictly between.
struct Bracket {
  float lo = 0.0f, hi = 0.0f;
  std::size_t below = 0, at_lo = 0, at_hi = 0, between = 0;
  std::unique_ptr<float[]> kept;

  Bracket(const std::vector<float>& v, std::size_t k) {
    const std::size_t n = v.size();
    // Two values from an evenly strided sample bracket rank k (Floyd and Rivest's selection).
    std::vector<float> sample(kSample);
    const std::size_t stride = n / kSample;
    for (std::size_t i = 0; i < kSample; ++i) sample[i] = v[i * stride];
    std::sort(sample.begin(), sample.end());
    const std::size_t at = k * kSample / n;
    lo = sample[at > kMargin ? at - kMargin : 0];
    hi = sample[std::min(kSample - 1, at + kMargin)];
    // One pass without branches (a branch on the value mispredicts half the time).
    kept.reset(new float[n + 1]);
    for (const float f : v) {
      below += f < lo;
      at_lo += f == lo;
      at_hi += f == hi;
      kept[between] = f;
      between += static_cast<std::size_t>((f > lo) & (f < hi));
    }
    if (lo == hi) at_hi = 0;
  }

  /// Where rank r lies: -1 below the bracket or above it (a miss), 0 at lo, 1 between (its rank
  /// among the values between in `r`), 2 at hi.
  int locate(std::size_t& r) const {
    if (r < below) return -1;
    r -= below;
    if (r < at_lo) return 0;
    r -= at_lo;
    if (r < between) return 1;
    r -= between;
    return r < at_hi ? 2 : -1;
  }

  /// The value of rank r among those between (0 <= r < between).
  float select(std::size_t r) {
    std::nth_element(kept.get(), kept.get() + r, kept.get() + between);
    return kept[r];
  }
};

}  // namespace

float kth_smallest(const std::vector<float>& v, std::size_t k) {
  if (v.size() < kFastFrom) return kth_smallest_reference(v, k);
  if (k >= v.size()) throw core::InputError("kth_smallest: rank out of range");
  Bracket b(v, k);
  std::size_t r = k;
  switch (b.locate(r)) {
    case 0: return b.lo;
    case 1: return b.select(r);
    case 2: return b.hi;
    default: return kth_smallest_reference(v, k);  // the bracket missed rank k
  }
}

std::pair<float, float> adjacent_smallest(const std::vector<float>& v, std::size_t k) {
  if (k == 0 || k >= v.size()) throw core::InputError("adjacent_smallest: rank out of range");
  if (v.size() >= kFastFrom) {
    Bracket b(v, k);
    std::size_t r0 = k - 1, r1 = k;
    const int w0 = b.locate(r0), w1 = b.locate(r1);
    if (w0 >= 0 && w1 >= 0) {
      // Both between: after selecting rank r1 the ranks below it lie before it, r0 their largest.
      if (w0 == 1 && w1 == 1) {
        const float upper = b.select(r1);
        return {*std::max_element(b.kept.get(), b.kept.get() + r1), upper};
      }
      const float upper = w1 == 0 ? b.lo : w1 == 2 ? b.hi : b.select(r1);
      const float lower = w0 == 0 ? b.lo : w0 == 2 ? b.hi : b.select(r0);
      return {lower, upper};
    }
  }
  std::vector<float> copy = v;
  std::nth_element(copy.begin(), copy.begin() + static_cast<std::ptrdiff_t>(k), copy.end());
  return {*std::max_element(copy.begin(), copy.begin() + static_cast<std::ptrdiff_t>(k)), copy[k]};
}

double median_of(const std::vector<float>& v) {
  if (v.empty()) throw core::InputError("median: no values");
  const std::size_t mid = v.size() / 2;
  if (v.size() % 2 == 1) return kth_smallest(v, mid);
  const auto [lower, upper] = adjacent_smallest(v, mid);
  return 0.5 * (static_cast<double>(lower) + upper);
}

}  // namespace sg::vision
