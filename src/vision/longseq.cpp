#include "sg/vision/longseq.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "sg/core/checker.hpp"
#include "sg/core/error.hpp"

namespace sg::vision {
namespace {

/// The disparity of every pixel of one row of `ref` matched against `other`, whose pixel x + sign
/// * d corresponds to ref's pixel x (sign -1: ref is the left image), each cost summed pixel by
/// pixel (the reference). `bad` and `cost` are scratch of num_disparities entries; out[x] = -1
/// where unmatched.
void match_row_reference(const std::uint8_t* ref, const std::uint8_t* other, int width, int sign,
                         const LongSeqParams& p, std::vector<std::uint8_t>& bad,
                         std::vector<int>& cost, float* out) {
  const int r = p.window_px / 2, n = p.num_disparities;
  // Costs as window sums of absolute differences: the thresholds times the window's pixels.
  const double window = p.window_px;
  const int cost_max = static_cast<int>(std::floor(p.cost_max * window));
  const int best_max = static_cast<int>(std::floor(p.best_max * window));
  for (int x = 0; x < width; ++x) {
    out[x] = -1.0f;
    // Every disparity's window must lie inside both images.
    const int lo = sign < 0 ? x - (n - 1) - r : x - r;
    const int hi = sign < 0 ? x + r : x + (n - 1) + r;
    if (lo < 0 || hi >= width) continue;
    int best = 255 * p.window_px;
    for (int d = 0; d < n; ++d) {
      const std::uint8_t* o = other + x + sign * d;
      int c = 0;
      for (int k = -r; k <= r; ++k) c += std::abs(int{ref[x + k]} - int{o[k]});
      cost[static_cast<size_t>(d)] = c;
      best = std::min(best, c);
    }
    if (best > best_max) continue;
    for (int d = 0; d < n; ++d)
      bad[static_cast<size_t>(d)] = cost[static_cast<size_t>(d)] > cost_max ? 1 : 0;
    if (std::find(bad.begin(), bad.end(), 1) == bad.end()) continue;  // textureless
    out[x] = static_cast<float>(longest_good_run(bad.data(), n));
  }
}

/// Scratch of the fast row matcher.
struct RowScratch {
  std::vector<std::int16_t> diff;  ///< [k * num_disparities + d] = |ref(k) - other(k + sign d)|
  std::vector<std::int16_t> cost;  ///< one pixel's window sums, d = 0 .. num_disparities - 1
  std::vector<std::uint8_t> bad;
};

/// match_row_reference with each pixel's costs as a running window sum along the row: the costs
/// of x are those of x - 1 plus the differences entering the window less those leaving it, all
/// disparities side by side (16-bit: a sum is at most 255 * 63). The sums are the same integers,
/// so the result is identical.
void match_row(const std::uint8_t* ref, const std::uint8_t* other, int width, int sign,
               const LongSeqParams& p, RowScratch& s, float* out) {
  const int r = p.window_px / 2, n = p.num_disparities;
  const int cost_max = static_cast<int>(std::floor(p.cost_max * p.window_px));
  const int best_max = static_cast<int>(std::floor(p.best_max * p.window_px));
  const auto un = static_cast<size_t>(n);
  s.diff.assign(un * static_cast<size_t>(width), 0);
  s.cost.assign(un, 0);
  s.bad.resize(un);
  for (int k = 0; k < width; ++k) {
    std::int16_t* dk = &s.diff[static_cast<size_t>(k) * un];
    const int v = ref[k];
    // The disparities whose pixel of `other` exists (the rest stay 0, outside every window used).
    if (sign < 0) {
      const std::uint8_t* o = other + k;
      for (int d = 0, end = std::min(n, k + 1); d < end; ++d)
        dk[d] = static_cast<std::int16_t>(std::abs(v - int{o[-d]}));
    } else {
      const std::uint8_t* o = other + k;
      for (int d = 0, end = std::min(n, width - k); d < end; ++d)
        dk[d] = static_cast<std::int16_t>(std::abs(v - int{o[d]}));
    }
  }
  // Pixels whose every window lies inside both images: x - (n - 1) - r >= 0 and x + r < width
  // (ref left, sign -1), or x - r >= 0 and x + (n - 1) + r < width (sign +1).
  const int x_lo = sign < 0 ? n - 1 + r : r;
  const int x_hi = sign < 0 ? width - 1 - r : width - n - r;  // inclusive
  std::int16_t* cost = s.cost.data();
  for (int x = 0; x < width; ++x) {
    out[x] = -1.0f;
    if (x < x_lo || x > x_hi) continue;
    if (x == x_lo) {
      for (int k = x - r; k <= x + r; ++k) {
        const std::int16_t* dk = &s.diff[static_cast<size_t>(k) * un];
        for (int d = 0; d < n; ++d) cost[d] = static_cast<std::int16_t>(cost[d] + dk[d]);
      }
    } else {
      const std::int16_t* in = &s.diff[static_cast<size_t>(x + r) * un];
      const std::int16_t* gone = &s.diff[static_cast<size_t>(x - r - 1) * un];
      for (int d = 0; d < n; ++d) cost[d] = static_cast<std::int16_t>(cost[d] + in[d] - gone[d]);
    }
    int best = cost[0];
    for (int d = 1; d < n; ++d) best = std::min(best, int{cost[d]});
    if (best > best_max) continue;
    // A window that matches at every disparity (no texture) says nothing: unmatched.
    bool any_bad = false;
    for (int d = 0; d < n; ++d) {
      s.bad[static_cast<size_t>(d)] = cost[d] > cost_max ? 1 : 0;
      any_bad |= cost[d] > cost_max;
    }
    if (!any_bad) continue;
    out[x] = static_cast<float>(longest_good_run(s.bad.data(), n));
  }
}

/// Checks the inputs of the LongSeq matchers and allocates the disparity.
void prepare_longseq(const cv::Mat& left, const cv::Mat& right, const LongSeqParams& p,
                     cv::Mat& disparity) {
  core::throw_if_invalid(validate(p), "invalid parameters");
  if (left.type() != CV_8UC1 || right.type() != CV_8UC1 || left.size() != right.size() ||
      left.empty())
    throw core::InputError(
        "longseq: left and right must be non-empty 8-bit grey images of one size");
  if (disparity.size() != left.size() || disparity.type() != CV_32FC1)
    disparity.create(left.size(), CV_32FC1);
}

/// Keeps, per left pixel, the smaller of its disparity and the one the right image's pixel x - d
/// found back (both_ways); -1 when the right pixel is unmatched.
void keep_smaller_both_ways(const std::vector<float>& from_right, int width, float* out) {
  for (int x = 0; x < width; ++x) {
    if (out[x] < 0.0f) continue;
    const float back = from_right[static_cast<size_t>(x - static_cast<int>(out[x]))];
    out[x] = back < 0.0f ? -1.0f : std::min(out[x], back);
  }
}

}  // namespace

std::vector<std::string> validate(const LongSeqParams& p) {
  std::vector<std::string> out;
  core::Checker c(out, "longseq");
  c.require(p.num_disparities >= 1 && p.num_disparities <= 1024, "num_disparities",
            p.num_disparities, "must be in 1..1024");
  c.require(p.window_px >= 1 && p.window_px % 2 == 1 && p.window_px <= 63, "window_px",
            p.window_px, "must be odd, in 1..63");
  c.require(std::isfinite(p.cost_max) && p.cost_max >= 0 && p.cost_max <= 255, "cost_max",
            p.cost_max, "must be in 0..255 (grey levels)");
  c.require(std::isfinite(p.best_max) && p.best_max >= 0 && p.best_max <= p.cost_max,
            "best_max", p.best_max, "must be in 0..cost_max (grey levels)");
  return out;
}

void good_run_lengths(const std::uint8_t* bad, int n, int* out) {
  for (int d = 0; d < n;) {
    if (bad[d]) {
      out[d++] = 1;
      continue;
    }
    int end = d;
    while (end < n && !bad[end]) ++end;
    std::fill(out + d, out + end, end - d);
    d = end;
  }
}

int longest_good_run(const std::uint8_t* bad, int n) {
  // The run ending at d grows by one on a good entry and restarts on a bad one; the first
  // strictly longest run wins.
  int length = 0, best_length = 0, best_end = -1;
  for (int d = 0; d < n; ++d) {
    length = bad[d] ? 0 : length + 1;
    const bool longer = length > best_length;
    best_length = longer ? length : best_length;
    best_end = longer ? d : best_end;
  }
  return best_end < 0 ? -1 : best_end - best_length + 1 + (best_length - 1) / 2;
}

void longseq_disparity_rows(const cv::Mat& left, const cv::Mat& right, const LongSeqParams& p,
                            cv::Mat& disparity, cv::Range rows) {
  prepare_longseq(left, right, p, disparity);
  const cv::Range r = rows == cv::Range::all() ? cv::Range(0, left.rows) : rows;
  const int w = left.cols;
  RowScratch scratch;
  std::vector<float> from_right(p.both_ways ? static_cast<size_t>(w) : 0);
  for (int y = r.start; y < r.end; ++y) {
    float* out = disparity.ptr<float>(y);
    match_row(left.ptr<std::uint8_t>(y), right.ptr<std::uint8_t>(y), w, -1, p, scratch, out);
    if (!p.both_ways) continue;
    match_row(right.ptr<std::uint8_t>(y), left.ptr<std::uint8_t>(y), w, +1, p, scratch,
              from_right.data());
    keep_smaller_both_ways(from_right, w, out);
  }
}

void longseq_disparity(const cv::Mat& left, const cv::Mat& right, const LongSeqParams& p,
                       cv::Mat& disparity) {
  disparity.release();
  longseq_disparity_rows(left, right, p, disparity, cv::Range::all());
}

void longseq_disparity_reference(const cv::Mat& left, const cv::Mat& right,
                                 const LongSeqParams& p, cv::Mat& disparity) {
  disparity.release();
  prepare_longseq(left, right, p, disparity);
  const int w = left.cols;
  std::vector<std::uint8_t> bad(static_cast<size_t>(p.num_disparities));
  std::vector<int> cost(static_cast<size_t>(p.num_disparities));
  std::vector<float> from_right(p.both_ways ? static_cast<size_t>(w) : 0);
  for (int y = 0; y < left.rows; ++y) {
    float* out = disparity.ptr<float>(y);
    match_row_reference(left.ptr<std::uint8_t>(y), right.ptr<std::uint8_t>(y), w, -1, p, bad,
                        cost, out);
    if (!p.both_ways) continue;
    match_row_reference(right.ptr<std::uint8_t>(y), left.ptr<std::uint8_t>(y), w, +1, p, bad,
                        cost, from_right.data());
    keep_smaller_both_ways(from_right, w, out);
  }
}

}  // namespace sg::vision
