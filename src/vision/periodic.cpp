#include "sg/vision/periodic.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace sg::vision {
namespace {

/// The x-gradient L(x + 1) - L(x - 1) clipped to +-cap, shifted to 0..2 cap (the matcher's
/// prefilter without its vertical smoothing); 0 difference at the first and last column.
cv::Mat prefiltered(const cv::Mat& left, int cap) {
  cv::Mat out(left.size(), CV_8U);
  for (int y = 0; y < left.rows; ++y) {
    const uint8_t* in = left.ptr<uint8_t>(y);
    uint8_t* o = out.ptr<uint8_t>(y);
    o[0] = o[left.cols - 1] = static_cast<uint8_t>(cap);
    for (int x = 1; x + 1 < left.cols; ++x)
      o[x] = static_cast<uint8_t>(std::clamp(int{in[x + 1]} - int{in[x - 1]}, -cap, cap) + cap);
  }
  return out;
}

/// Cells of kCell x kCell pixels: C_s is summed over the cells a block covers, not per pixel,
/// and over every other row of a cell (a repeat along the row shows in any of them).
constexpr int kCell = 4;
constexpr int kRowStep = 2;

/// C_s per cell (CV_16U, cells x cells of `pre`): the sum over the cell of |P(x) - P(x - s)|,
/// pixels x < s (which have no x - s) counted with the largest difference, 2 cap.
void cell_costs(const cv::Mat& pre, int s, int cap, std::vector<uint16_t>& columns,
                cv::Mat& cells) {
  const int width = pre.cols;
  for (int cy = 0; cy < cells.rows; ++cy) {
    const auto largest = static_cast<uint16_t>(kCell / kRowStep * 2 * cap);
    std::fill(columns.begin(), columns.begin() + s, largest);
    std::fill(columns.begin() + s, columns.end(), static_cast<uint16_t>(0));
    for (int r = 0; r < kCell; r += kRowStep) {
      const uint8_t* row = pre.ptr<uint8_t>(cy * kCell + r);
      uint16_t* sum = columns.data();
      for (int x = s; x < width; ++x) {
        const uint8_t a = row[x], b = row[x - s];
        sum[x] = static_cast<uint16_t>(sum[x] + (std::max(a, b) - std::min(a, b)));
      }
    }
    uint16_t* out = cells.ptr<uint16_t>(cy);
    for (int cx = 0; cx < cells.cols; ++cx) {
      const uint16_t* c = columns.data() + cx * kCell;
      out[cx] = static_cast<uint16_t>(c[0] + c[1] + c[2] + c[3]);
    }
  }
}

/// C_s on the cell grid (CV_32S, into `cost`): the cell costs summed over the block_cells x
/// block_cells cells around each cell (fewer at the grid's border).
void shift_cost(const cv::Mat& pre, int s, int block_cells, int cap,
                std::vector<uint16_t>& columns, cv::Mat& cells, cv::Mat& across,
                cv::Mat& cost) {
  cell_costs(pre, s, cap, columns, cells);
  const int half = block_cells / 2, rows = cells.rows, cols = cells.cols;
  across.create(cells.size(), CV_32S);
  cost.create(cells.size(), CV_32S);
  for (int y = 0; y < rows; ++y) {  // sums along the row, one offset at a time
    const uint16_t* c = cells.ptr<uint16_t>(y);
    int32_t* a = across.ptr<int32_t>(y);
    std::fill(a, a + cols, 0);
    for (int j = -half; j <= half; ++j) {
      const int from = std::max(0, -j), to = std::min(cols, cols - j);
      for (int x = from; x < to; ++x) a[x] += c[x + j];
    }
  }
  for (int y = 0; y < rows; ++y) {  // then down the columns
    int32_t* out = cost.ptr<int32_t>(y);
    std::fill(out, out + cols, 0);
    for (int k = std::max(0, y - half); k <= std::min(rows - 1, y + half); ++k) {
      const int32_t* a = across.ptr<int32_t>(k);
      for (int x = 0; x < cols; ++x) out[x] += a[x];
    }
  }
}

}  // namespace

cv::Mat periodic_mask(const cv::Mat& left, const core::BmParams& p) {
  CV_Assert(left.type() == CV_8UC1);
  // Not Mat::zeros: its MatExpr goes through OpenCV state that TSan, without OpenCV built for it,
  // reports as a race between two farm workers.
  cv::Mat mask(left.size(), CV_8U, cv::Scalar(0));
  const int max_shift = std::min(p.num_disparities, left.cols / 2);
  if (p.periodic_ratio <= 0.0 || max_shift <= 2 || left.rows < kCell) return mask;
  const cv::Mat pre = prefiltered(left, p.prefilter_cap);
  const int cap = p.prefilter_cap;
  const int block_cells = std::max(1, (p.block_size + kCell / 2) / kCell) | 1;
  std::vector<uint16_t> columns(left.cols);
  cv::Mat cells(left.rows / kCell, left.cols / kCell, CV_16U), across, one, best, cost;
  shift_cost(pre, 1, block_cells, cap, columns, cells, across, one);
  shift_cost(pre, 2, block_cells, cap, columns, cells, across, best);
  for (int s = 3; s < max_shift; ++s) {
    shift_cost(pre, s, block_cells, cap, columns, cells, across, cost);
    cv::min(best, cost, best);
  }
  // A pixel takes the verdict of its cell (the last cell for the few pixels past the grid).
  for (int y = 0; y < left.rows; ++y) {
    const int cy = std::min(y / kCell, cells.rows - 1);
    const int32_t* b = best.ptr<int32_t>(cy);
    const int32_t* o = one.ptr<int32_t>(cy);
    uint8_t* m = mask.ptr<uint8_t>(y);
    for (int x = 0; x < left.cols; ++x) {
      const int cx = std::min(x / kCell, cells.cols - 1);
      if (b[cx] < p.periodic_ratio * o[cx]) m[x] = 255;
    }
  }
  return mask;
}

}  // namespace sg::vision
