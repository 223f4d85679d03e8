#include "sg/vision/coarse_fill.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "sg/vision/stereo_bm.hpp"

namespace sg::vision {
namespace {

/// Two disparities agree when they differ by at most this many px, or this share of the larger.
constexpr float kAgreePx = 1.0f;
constexpr float kAgreeShare = 0.25f;

float agreement(float d) { return std::max(kAgreePx, kAgreeShare * d); }

/// Whether `coarse` may fill a hole whose row has the valid pixels `left` and `right` (< 0: none)
/// beside it: unless both exist and agree with each other, anything may; if they do, the hole
/// lies inside one surface, and the fill must agree with it.
bool fits_rims(float coarse, float left, float right) {
  if (left < 0 || right < 0) return true;
  const float lo = std::min(left, right), hi = std::max(left, right);
  if (hi - lo > agreement(hi)) return true;
  return coarse >= lo - agreement(lo) && coarse <= hi + agreement(hi);
}

}  // namespace

int coarse_fill_reach(const core::BmParams& p) { return (p.block_size + 1) / 2; }

void fill_from_half_size(const cv::Mat& left, const cv::Mat& right, const core::BmParams& p,
                         RowMatcher match, cv::Mat& disp) {
  CV_Assert(disp.type() == CV_32F && disp.size() == left.size());
  core::BmParams half_p = p;
  half_p.min_disparity = p.min_disparity / 2;
  half_p.num_disparities = std::max(16, (p.num_disparities / 2 + 15) / 16 * 16);
  const cv::Size half_size(left.cols / 2, left.rows / 2);
  if (half_size.width < kCoarseFillMinHalfWidth ||
      half_p.min_disparity + half_p.num_disparities + p.block_size >= half_size.width ||
      p.block_size >= half_size.height) {
    return;
  }
  cv::Mat invalid = disp < 0;
  if (cv::countNonZero(invalid) == 0) return;
  cv::Mat reach;  // city-block distance of each invalid pixel to the nearest valid one
  cv::distanceTransform(invalid, reach, cv::DIST_L1, 3, CV_32F);

  cv::Mat half_left, half_right, half(half_size, CV_32F);
  cv::resize(left, half_left, half_size, 0, 0, cv::INTER_AREA);
  cv::resize(right, half_right, half_size, 0, 0, cv::INTER_AREA);
  match(half_left, half_right, half_p, half, cv::Range::all());
  if (half_p.left_band) {
    match_left_band_rows(match, half_left, half_right, half_p, half, cv::Range::all());
  }
  filter_speckles(half, half_p);

  const float min_reach = static_cast<float>(coarse_fill_reach(p));
  std::vector<float> left_rim(disp.cols);
  for (int y = 0; y < disp.rows; ++y) {
    float* d = disp.ptr<float>(y);
    const float* r = reach.ptr<float>(y);
    const float* h = half.ptr<float>(std::min(y / 2, half.rows - 1));
    float rim = -1.0f;  // the nearest valid disparity to the left, then to the right
    for (int x = 0; x < disp.cols; ++x) {
      if (d[x] >= 0) rim = d[x];
      left_rim[x] = rim;
    }
    rim = -1.0f;
    for (int x = disp.cols - 1; x >= 0; --x) {  // fills only pixels left of those it reads
      if (d[x] >= 0) {
        rim = d[x];
        continue;
      }
      if (r[x] <= min_reach) continue;
      const float coarse = 2.0f * h[std::min(x / 2, half.cols - 1)];
      if (coarse >= 0 && fits_rims(coarse, left_rim[x], rim)) d[x] = coarse;
    }
  }
}

}  // namespace sg::vision
