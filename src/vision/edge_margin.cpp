#include "sg/vision/edge_margin.hpp"

#include <algorithm>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "sg/core/error.hpp"

namespace sg::vision {
namespace {

/// Marks (255 in `out`, stride `out_step` elements) the thin runs of one line of `n` disparities
/// read with stride `in_step`.
void mark_thin_runs(const float* d, int n, std::ptrdiff_t in_step, float step, int max_width,
                    std::uint8_t* out, std::ptrdiff_t out_step) {
  int a = 0;
  while (a < n) {
    const float da = d[a * in_step];
    if (!(da >= 0.0f)) {
      ++a;
      continue;
    }
    int b = a + 1;
    float lo = da;
    while (b < n) {
      const float cur = d[b * in_step], prev = d[(b - 1) * in_step];
      if (!(cur >= 0.0f) || std::abs(cur - prev) > step) break;
      lo = std::min(lo, cur);
      ++b;
    }
    // [a, b) is a run of similar disparity; both ends must be farther surfaces or invalid.
    const auto bounds = [&](int i) {
      if (i < 0 || i >= n) return false;  // the image border: the object may go on outside
      const float v = d[i * in_step];
      return !(v >= 0.0f) || v < lo - step;
    };
    if (b - a <= max_width && bounds(a - 1) && bounds(b))
      for (int i = a; i < b; ++i) out[i * out_step] = 255;
    a = b;
  }
}

}  // namespace

void mark_thin_structures(const cv::Mat& disp, int margin_px, double step_px, int max_width_px,
                          cv::Mat& mask) {
  if (disp.type() != CV_32FC1) throw core::InputError("thin structures: disparity must be CV_32F");
  mask.create(disp.size(), CV_8UC1);
  mask.setTo(0);
  const float step = static_cast<float>(step_px);
  cv::Mat thin = cv::Mat::zeros(disp.size(), CV_8UC1);
  for (int y = 0; y < disp.rows; ++y)
    mark_thin_runs(disp.ptr<float>(y), disp.cols, 1, step, max_width_px, thin.ptr<std::uint8_t>(y),
                   1);
  const std::ptrdiff_t in_stride = static_cast<std::ptrdiff_t>(disp.step1());
  const std::ptrdiff_t out_stride = static_cast<std::ptrdiff_t>(thin.step1());
  for (int x = 0; x < disp.cols; ++x)
    mark_thin_runs(disp.ptr<float>(0) + x, disp.rows, in_stride, step, max_width_px,
                   thin.ptr<std::uint8_t>(0) + x, out_stride);
  cv::Mat hi;
  const int r = std::max(0, margin_px);
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * r + 1, 2 * r + 1));
  cv::dilate(disp, hi, kernel, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(-1.0));
  for (int y = 0; y < disp.rows; ++y) {
    const float* d = disp.ptr<float>(y);
    const float* h = hi.ptr<float>(y);
    const std::uint8_t* t = thin.ptr<std::uint8_t>(y);
    std::uint8_t* m = mask.ptr<std::uint8_t>(y);
    for (int x = 0; x < disp.cols; ++x)
      if (t[x] && h[x] <= d[x] + step) m[x] = 255;
  }
}

void unmark_thin_structures(const cv::Mat& disp, int margin_px, double step_px, cv::Mat& edges) {
  if (margin_px <= 0) return;
  cv::Mat thin;
  mark_thin_structures(disp, margin_px, step_px, 2 * margin_px + 1, thin);
  edges.setTo(0, thin);
}

void grow_danger_into_edges(const cv::Mat& disp, const cv::Mat& edges, int iterations,
                            double step_px, int open_size, cv::Mat& danger, cv::Mat& ttc,
                            cv::Mat& velocity) {
  if (disp.type() != CV_32FC1 || edges.type() != CV_8UC1 || danger.type() != CV_8UC1 ||
      ttc.type() != CV_32FC1 || edges.size() != disp.size() || danger.size() != disp.size() ||
      ttc.size() != disp.size())
    throw core::InputError("danger growth: maps must be CV_32F / CV_8U of the same size");
  const bool with_velocity = !velocity.empty();
  if (with_velocity && (velocity.type() != CV_32FC3 || velocity.size() != disp.size()))
    throw core::InputError("danger growth: the velocity map must be CV_32FC3 of the same size");
  cv::Mat seeds;  // not a header of `danger`: the opening must not overwrite it
  if (open_size > 1) {
    const cv::Mat k = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(open_size, open_size));
    cv::morphologyEx(danger, seeds, cv::MORPH_OPEN, k);
  } else {
    seeds = danger;
  }
  cv::Mat grown = seeds.clone();
  const float step = static_cast<float>(step_px);
  const int w = disp.cols, h = disp.rows;
  std::vector<cv::Point> added;
  for (int it = 0; it < iterations; ++it) {
    added.clear();
    for (int y = 0; y < h; ++y) {
      const std::uint8_t* e = edges.ptr<std::uint8_t>(y);
      const std::uint8_t* g = grown.ptr<std::uint8_t>(y);
      const float* d = disp.ptr<float>(y);
      for (int x = 0; x < w; ++x) {
        if (!e[x] || g[x] || !(d[x] >= 0.0f)) continue;
        // The dangerous neighbour nearest in disparity, if close enough.
        int best_x = -1, best_y = -1;
        float best = step;
        for (int yy = std::max(0, y - 1); yy <= std::min(h - 1, y + 1); ++yy) {
          const std::uint8_t* gn = grown.ptr<std::uint8_t>(yy);
          const float* dn = disp.ptr<float>(yy);
          for (int xx = std::max(0, x - 1); xx <= std::min(w - 1, x + 1); ++xx) {
            if (!gn[xx]) continue;
            const float diff = std::abs(dn[xx] - d[x]);
            if (diff <= best) {
              best = diff;
              best_x = xx;
              best_y = yy;
            }
          }
        }
        if (best_x < 0) continue;
        added.emplace_back(x, y);
        ttc.at<float>(y, x) = ttc.at<float>(best_y, best_x);
        if (with_velocity) velocity.at<cv::Vec3f>(y, x) = velocity.at<cv::Vec3f>(best_y, best_x);
      }
    }
    if (added.empty()) break;
    for (const cv::Point& p : added) grown.at<std::uint8_t>(p) = 255;
  }
  // The result: the original danger (min_area and the opening still apply later) plus the rims.
  cv::bitwise_or(danger, grown, danger);
}

}  // namespace sg::vision
