#include "sg/vision/left_band.hpp"

#include <algorithm>
#include <cmath>

namespace sg::vision {
namespace {

/// The right image's own disparities over its columns [0, columns), searched over the full range:
/// `match` on the pair cut to what those searches read, mirrored (the right image becomes the
/// left one). Returns the mirrored map: the right column xr is at column cut - 1 - xr.
cv::Mat right_view_disparities(RowMatcher match, const cv::Mat& left, const cv::Mat& right,
                               const core::BmParams& p, int columns, cv::Range rows) {
  const int h = p.block_size / 2;
  const int cut = std::min(left.cols, columns + p.min_disparity + p.num_disparities + h + 1);
  cv::Mat mirrored_left, mirrored_right, disp;
  cv::flip(right.colRange(0, cut), mirrored_left, 1);
  cv::flip(left.colRange(0, cut), mirrored_right, 1);
  match(mirrored_left, mirrored_right, p, disp, rows);
  return disp;
}

}  // namespace

void match_left_band_rows(RowMatcher match, const cv::Mat& left, const cv::Mat& right,
                          const core::BmParams& p, cv::Mat& disp, cv::Range rows) {
  if (rows == cv::Range::all()) rows = cv::Range(0, left.rows);
  if (rows.empty()) return;
  const int h = p.block_size / 2, md = p.min_disparity;
  const int band_end = std::min(left.cols, md + p.num_disparities - 1 + h);
  core::BmParams strip_params = p;
  cv::Mat strip;
  for (int n = 16; n < p.num_disparities; n += 16) {
    const int from = md + n - 1 + h;
    const int to = std::min(from + 16, band_end);
    const int cut = to + h + 1;  // the prefilter of the last block column reads one further
    if (cut > left.cols) break;
    strip_params.num_disparities = n;
    match(left.colRange(0, cut), right.colRange(0, cut), strip_params, strip, rows);
    // A winner at the strip's largest disparity is a minimum on one side only: the true one may
    // lie beyond the range (a near point), so it is not kept.
    const float edge = static_cast<float>(md + n - 1);
    for (int y = rows.start; y < rows.end; ++y) {
      const float* s = strip.ptr<float>(y);
      float* d = disp.ptr<float>(y);
      for (int x = from; x < to; ++x) d[x] = s[x] >= edge ? -1.0f : s[x];
    }
  }
  if (p.lr_max_diff < 0) return;
  // A strip searches less than the full range, so a near point whose disparity exceeds it takes
  // an alias (a period of the texture) that no other candidate of the strip contests. The right
  // pixel the alias points to knows better: its own match over the full range must agree.
  const cv::Mat mirrored = right_view_disparities(match, left, right, p, band_end, rows);
  const int last = mirrored.cols - 1;
  for (int y = rows.start; y < rows.end; ++y) {
    float* d = disp.ptr<float>(y);
    const float* r = mirrored.ptr<float>(y);
    for (int x = 0; x < band_end; ++x) {
      if (!(d[x] >= 0.0f)) continue;
      const int xr = x - static_cast<int>(std::lround(d[x]));
      const float back = xr >= 0 && last - xr >= 0 ? r[last - xr] : -1.0f;
      if (!(back >= 0.0f) || std::abs(back - d[x]) > static_cast<float>(p.lr_max_diff))
        d[x] = -1.0f;
    }
  }
}

}  // namespace sg::vision
