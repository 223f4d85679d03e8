// periodic_mask: a SIMD kernel (Google Highway, compiled once per x86 target and dispatched at
// run time) for the shift costs, and periodic_mask_reference, the scalar reference it must equal
// (integer sums: the order of the additions does not change them).
#include "sg/vision/periodic.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <vector>

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "src/vision/periodic.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace sg::vision::periodic_detail {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

/// |a - b| of unsigned lanes.
template <class V>
V AbsDiffLanes(V a, V b) {
  return hn::Or(hn::SaturatedSub(a, b), hn::SaturatedSub(b, a));
}

/// diff[x] = |r0[x] - r0[x - s]| + |r1[x] - r1[x - s]| for s <= x < width (each term <= 126, so
/// the sum fits a byte); the caller fills x < s.
void RowPairDiffs(const std::uint8_t* r0, const std::uint8_t* r1, int width, int s,
                  std::uint8_t* diff) {
  const hn::ScalableTag<std::uint8_t> d;
  const int n = static_cast<int>(hn::Lanes(d));
  int x = s;
  for (; x + n <= width; x += n)
    hn::StoreU(hn::Add(AbsDiffLanes(hn::LoadU(d, r0 + x), hn::LoadU(d, r0 + x - s)),
                       AbsDiffLanes(hn::LoadU(d, r1 + x), hn::LoadU(d, r1 + x - s))),
               d, diff + x);
  for (; x < width; ++x) {
    const int a = std::abs(int{r0[x]} - int{r0[x - s]});
    const int b = std::abs(int{r1[x]} - int{r1[x - s]});
    diff[x] = static_cast<std::uint8_t>(a + b);
  }
}

/// out[c] = diff[4 c] + ... + diff[4 c + 3] for c < cells: the bytes' sums of four, formed by
/// viewing the bytes as 16-bit lanes and those as 32-bit lanes.
void CellSums(const std::uint8_t* diff, int cells, std::int32_t* out) {
  int c = 0;
#if HWY_TARGET != HWY_SCALAR  // one lane cannot be viewed as wider lanes
  const hn::ScalableTag<std::uint8_t> d8;
  const hn::Repartition<std::uint16_t, decltype(d8)> d16;
  const hn::Repartition<std::uint32_t, decltype(d8)> d32;
  const hn::Repartition<std::int32_t, decltype(d8)> di;
  const int n = static_cast<int>(hn::Lanes(d32));  // cells per vector
  for (; c + n <= cells; c += n) {
    const auto v16 = hn::BitCast(d16, hn::LoadU(d8, diff + 4 * c));
    const auto pairs = hn::Add(hn::And(v16, hn::Set(d16, 0xFF)), hn::ShiftRight<8>(v16));
    const auto p32 = hn::BitCast(d32, pairs);
    const auto quads = hn::Add(hn::And(p32, hn::Set(d32, 0xFFFF)), hn::ShiftRight<16>(p32));
    hn::StoreU(hn::BitCast(di, quads), di, out + c);
  }
#endif
  for (; c < cells; ++c) {
    const std::uint8_t* q = diff + 4 * c;
    out[c] = q[0] + q[1] + q[2] + q[3];
  }
}

/// acc[x] += add[x] - sub[x] for x < n (either may be null: nothing added or taken).
void AddSubRow(std::int32_t* acc, const std::int32_t* add, const std::int32_t* sub, int n) {
  const hn::ScalableTag<std::int32_t> d;
  const int lanes = static_cast<int>(hn::Lanes(d));
  int x = 0;
  for (; x + lanes <= n; x += lanes) {
    auto v = hn::LoadU(d, acc + x);
    if (add) v = hn::Add(v, hn::LoadU(d, add + x));
    if (sub) v = hn::Sub(v, hn::LoadU(d, sub + x));
    hn::StoreU(v, d, acc + x);
  }
  for (; x < n; ++x) acc[x] += (add ? add[x] : 0) - (sub ? sub[x] : 0);
}

/// out[x] = padded[x] + ... + padded[x + width - 1] for x < n; with `min`, out[x] takes the
/// smaller of that and its own value.
void WindowRow(const std::int32_t* padded, int n, int width, bool min, std::int32_t* out) {
  const hn::ScalableTag<std::int32_t> d;
  const int lanes = static_cast<int>(hn::Lanes(d));
  int x = 0;
  for (; x + lanes <= n; x += lanes) {
    auto sum = hn::LoadU(d, padded + x);
    for (int j = 1; j < width; ++j) sum = hn::Add(sum, hn::LoadU(d, padded + x + j));
    if (min) sum = hn::Min(sum, hn::LoadU(d, out + x));
    hn::StoreU(sum, d, out + x);
  }
  for (; x < n; ++x) {
    std::int32_t sum = 0;
    for (int j = 0; j < width; ++j) sum += padded[x + j];
    out[x] = min ? std::min(sum, out[x]) : sum;
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace sg::vision::periodic_detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sg::vision {
namespace periodic_detail {
HWY_EXPORT(RowPairDiffs);
HWY_EXPORT(CellSums);
HWY_EXPORT(AddSubRow);
HWY_EXPORT(WindowRow);
}  // namespace periodic_detail

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

/// What both versions share: the prefiltered image, the cell grid, and the block cost C_s on it.
struct Grid {
  cv::Mat pre;  ///< prefiltered(left)
  int cap = 0;
  int half = 0;  ///< block_cells / 2
  int rows = 0, cols = 0;
};

/// Fills `cost` (CV_32S, grid.rows x grid.cols) with C_s, or with min(its own value, C_s) when
/// `min` is set.
using ShiftCost = std::function<void(const Grid& grid, int s, bool min, cv::Mat& cost)>;

/// The mask from C_s: marked where min over 2 <= s < max_shift of C_s < ratio * C_1.
cv::Mat mask_from_costs(const cv::Mat& left, const core::BmParams& p, const ShiftCost& shift_cost) {
  CV_Assert(left.type() == CV_8UC1);
  // Not Mat::zeros: its MatExpr goes through OpenCV state that TSan, without OpenCV built for it,
  // reports as a race between two farm workers.
  cv::Mat mask(left.size(), CV_8U, cv::Scalar(0));
  const int max_shift = std::min(p.num_disparities, left.cols / 2);
  if (p.periodic_ratio <= 0.0 || max_shift <= 2 || left.rows < kCell) return mask;
  Grid grid;
  grid.pre = prefiltered(left, p.prefilter_cap);
  grid.cap = p.prefilter_cap;
  grid.half = (std::max(1, (p.block_size + kCell / 2) / kCell) | 1) / 2;
  grid.rows = left.rows / kCell;
  grid.cols = left.cols / kCell;
  cv::Mat one(grid.rows, grid.cols, CV_32S), best(grid.rows, grid.cols, CV_32S);
  shift_cost(grid, 1, false, one);
  shift_cost(grid, 2, false, best);
  for (int s = 3; s < max_shift; ++s) shift_cost(grid, s, true, best);
  // A pixel takes the verdict of its cell (the last cell for the few pixels past the grid).
  for (int y = 0; y < left.rows; ++y) {
    const int cy = std::min(y / kCell, grid.rows - 1);
    const int32_t* b = best.ptr<int32_t>(cy);
    const int32_t* o = one.ptr<int32_t>(cy);
    uint8_t* m = mask.ptr<uint8_t>(y);
    for (int x = 0; x < left.cols; ++x) {
      const int cx = std::min(x / kCell, grid.cols - 1);
      if (b[cx] < p.periodic_ratio * o[cx]) m[x] = 255;
    }
  }
  return mask;
}

/// The cost of the x < s pixels, which have no x - s: the largest difference, 2 cap, per row.
int no_partner_cost(const Grid& grid) { return kCell / kRowStep * 2 * grid.cap; }

/// The reference: C_s per cell, pixel by pixel, then the cells a block covers, one by one.
void shift_cost_reference(const Grid& grid, int s, bool min, cv::Mat& cost) {
  const int width = grid.pre.cols, half = grid.half;
  std::vector<int32_t> columns(static_cast<size_t>(width));
  cv::Mat cells(grid.rows, grid.cols, CV_32S);
  for (int cy = 0; cy < grid.rows; ++cy) {
    std::fill(columns.begin(), columns.begin() + s, no_partner_cost(grid));
    std::fill(columns.begin() + s, columns.end(), 0);
    for (int r = 0; r < kCell; r += kRowStep) {
      const uint8_t* row = grid.pre.ptr<uint8_t>(cy * kCell + r);
      for (int x = s; x < width; ++x) columns[x] += std::abs(int{row[x]} - int{row[x - s]});
    }
    int32_t* out = cells.ptr<int32_t>(cy);
    for (int cx = 0; cx < grid.cols; ++cx) {
      out[cx] = 0;
      for (int i = 0; i < kCell; ++i) out[cx] += columns[cx * kCell + i];
    }
  }
  for (int y = 0; y < grid.rows; ++y) {
    int32_t* out = cost.ptr<int32_t>(y);
    for (int x = 0; x < grid.cols; ++x) {
      int32_t sum = 0;  // the cells of the block, fewer at the grid's border
      for (int k = std::max(0, y - half); k <= std::min(grid.rows - 1, y + half); ++k)
        for (int j = std::max(0, x - half); j <= std::min(grid.cols - 1, x + half); ++j)
          sum += cells.at<int32_t>(k, j);
      out[x] = min ? std::min(out[x], sum) : sum;
    }
  }
}

/// The same sums with the kernels: the two rows' differences and their sums of four at once,
/// then a running sum down the block's cell rows and a window along them.
class FastShiftCost {
 public:
  void operator()(const Grid& grid, int s, bool min, cv::Mat& cost) {
    const int width = grid.pre.cols, half = grid.half, cols = grid.cols;
    diff_.resize(static_cast<size_t>(width));
    cells_.create(grid.rows, cols, CV_32S);
    // x < s has no x - s; RowPairDiffs writes only x >= s, so this holds for every cell row
    std::fill(diff_.begin(), diff_.begin() + s, static_cast<uint8_t>(no_partner_cost(grid)));
    for (int cy = 0; cy < grid.rows; ++cy) {
      HWY_DYNAMIC_DISPATCH(periodic_detail::RowPairDiffs)
      (grid.pre.ptr<uint8_t>(cy * kCell), grid.pre.ptr<uint8_t>(cy * kCell + kRowStep), width, s,
       diff_.data());
      HWY_DYNAMIC_DISPATCH(periodic_detail::CellSums)(diff_.data(), cols, cells_.ptr<int32_t>(cy));
    }
    // down: padded_ holds the block's cell rows summed, with `half` zeros either side
    padded_.assign(static_cast<size_t>(cols + 2 * half), 0);
    int32_t* down = padded_.data() + half;
    for (int k = 0; k < std::min(half, grid.rows); ++k)
      HWY_DYNAMIC_DISPATCH(periodic_detail::AddSubRow)(down, cells_.ptr<int32_t>(k), nullptr, cols);
    for (int y = 0; y < grid.rows; ++y) {
      const int enter = y + half, leave = y - half - 1;
      HWY_DYNAMIC_DISPATCH(periodic_detail::AddSubRow)
      (down, enter < grid.rows ? cells_.ptr<int32_t>(enter) : nullptr,
       leave >= 0 ? cells_.ptr<int32_t>(leave) : nullptr, cols);
      HWY_DYNAMIC_DISPATCH(periodic_detail::WindowRow)
      (padded_.data(), cols, 2 * half + 1, min, cost.ptr<int32_t>(y));
    }
  }

 private:
  std::vector<uint8_t> diff_;
  std::vector<int32_t> padded_;
  cv::Mat cells_;
};

}  // namespace

cv::Mat periodic_mask(const cv::Mat& left, const core::BmParams& p) {
  FastShiftCost fast;
  return mask_from_costs(left, p, std::ref(fast));
}

cv::Mat periodic_mask_reference(const cv::Mat& left, const core::BmParams& p) {
  return mask_from_costs(left, p, shift_cost_reference);
}

}  // namespace sg::vision
#endif  // HWY_ONCE
