// The plain scalar reference of the fast matcher: every block sum computed from its definition.
#include <algorithm>
#include <bit>
#include <climits>
#include <cstdint>
#include <vector>

#include "sg/vision/stereo_fast.hpp"
#include "stereo_fast_common.hpp"

namespace sg::vision {

void match_fast_reference(const cv::Mat& left, const cv::Mat& right, const core::BmParams& p,
                          cv::Mat& disp, cv::Range rows) {
  using fast_detail::kInvalid16;
  const int height = left.rows, width = left.cols;
  if (rows == cv::Range::all()) rows = cv::Range(0, height);
  disp.create(left.size(), CV_32F);
  disp.rowRange(rows).setTo(-1.0f);
  const int nd = p.num_disparities, md = p.min_disparity, h = p.block_size / 2;
  const int x0 = md + nd - 1 + h, x1 = width - h;
  const int y0 = std::max(rows.start, h), y1 = std::min(rows.end, height - h);
  if (y0 >= y1 || x0 >= x1) return;

  // Whole-image transforms: the reference does not bother about tiles.
  cv::Mat pl, pr, cl, cr;
  fast_detail::prefilter_rows(left, p.prefilter_cap, 0, height, pl);
  fast_detail::prefilter_rows(right, p.prefilter_cap, 0, height, pr);
  const bool census = p.cost == core::MatchCost::kCensus;
  if (census) {
    fast_detail::census_rows(left, 0, height, cl);
    fast_detail::census_rows(right, 0, height, cr);
  }
  auto pixel_cost = [&](int y, int xl, int xr) {
    if (census)
      return std::popcount(static_cast<std::uint32_t>(cl.at<int>(y, xl) ^ cr.at<int>(y, xr)));
    return std::abs(static_cast<int>(pl.at<std::uint8_t>(y, xl)) - pr.at<std::uint8_t>(y, xr));
  };

  cv::Mat out16(y1 - y0, width, CV_16S, cv::Scalar(kInvalid16));
  std::vector<int> cost(static_cast<size_t>(width) * nd);
  std::vector<int> best(width);
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      for (int d = 0; d < nd; ++d) {
        int sum = 0;
        for (int dy = -h; dy <= h; ++dy)
          for (int dx = -h; dx <= h; ++dx) sum += pixel_cost(y + dy, x + dx, x + dx - md - d);
        cost[static_cast<size_t>(x) * nd + d] = sum;
      }
    }
    for (int x = x0; x < x1; ++x) {
      const int* c = &cost[static_cast<size_t>(x) * nd];
      int b = 0;
      for (int d = 1; d < nd; ++d)
        if (c[d] <= c[b]) b = d;  // ties: the largest disparity, as StereoBM
      best[x] = b;
      int texture = 0;
      for (int dy = -h; dy <= h; ++dy)
        for (int dx = -h; dx <= h; ++dx)
          texture += std::abs(pl.at<std::uint8_t>(y + dy, x + dx) - p.prefilter_cap);
      if (texture < p.texture_threshold) continue;
      if (p.uniqueness_ratio > 0) {
        const int thresh = c[b] + c[b] * p.uniqueness_ratio / 100;
        bool unique = true;
        for (int d = 0; d < nd; ++d)
          if ((d < b - 1 || d > b + 1) && c[d] <= thresh) unique = false;
        if (!unique) continue;
      }
      if (p.lr_max_diff >= 0) {
        // The right pixel's own winner among the left pixels that see it.
        const int xr = x - md - b;
        int rb = -1, rc = INT_MAX;
        for (int d = 0; d < nd; ++d) {
          const int xl = xr + md + d;
          if (xl < x0 || xl >= x1) continue;
          if (cost[static_cast<size_t>(xl) * nd + d] < rc) {
            rc = cost[static_cast<size_t>(xl) * nd + d];
            rb = d;
          }
        }
        if (std::abs(rb - b) > p.lr_max_diff) continue;
      }
      const int d16 =
          (b > 0 && b < nd - 1) ? subpixel_disparity16(b, c[b - 1], c[b], c[b + 1]) : b * 16;
      out16.at<std::int16_t>(y - y0, x) = static_cast<std::int16_t>(d16 + md * 16);
    }
  }
  fast_detail::store_disparity16(out16, y0, disp);
}

}  // namespace sg::vision
