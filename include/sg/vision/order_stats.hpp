#pragma once
/// Exact order statistics of large float samples: the medians of an obstacle's pixels.
///
/// A blob of a box 1.5 m away covers 195,000 pixels at 640x480; std::nth_element over them took
/// about 1.1 ms a median, two medians a blob (depth and TTC), and made the frames with something
/// near cost more than the others. kth_smallest brackets rank k between two values of an evenly
/// strided sample of 1024 (Floyd and Rivest's selection) and selects among the few values between
/// them after one pass that has no branch on the values: 0.4 ms on that blob. Both give the same
/// value, the one of rank k in the sorted sample, ties included (the disparities lie on a 1/16 px
/// grid).
#include <cstddef>
#include <utility>
#include <vector>

namespace sg::vision {

/// The value of rank k (0-based) of v sorted ascending; v must hold finite values, k < v.size().
/// The sampled bracket for large samples (the reference when it misses), kth_smallest_reference
/// for small ones; v is left as it was.
float kth_smallest(const std::vector<float>& v, std::size_t k);

/// The values of ranks k - 1 and k (0 < k < v.size()) from one pass: the two middle values of an
/// even count. The same values as kth_smallest_reference at both ranks.
std::pair<float, float> adjacent_smallest(const std::vector<float>& v, std::size_t k);

/// The same by std::nth_element on a copy: the reference the fast path is tested against.
float kth_smallest_reference(const std::vector<float>& v, std::size_t k);

/// The median of v (not empty): the middle value, or for an even count the mean (in double) of
/// the two middle values.
double median_of(const std::vector<float>& v);

}  // namespace sg::vision
