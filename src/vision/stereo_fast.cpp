// The fast matcher's SIMD kernel (Google Highway, compiled once per x86 target and dispatched at
// run time) and its driver. The scalar reference is stereo_fast_reference.cpp.
#include "sg/vision/stereo_fast.hpp"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <vector>

#include "stereo_fast_common.hpp"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "src/vision/stereo_fast.cpp"
#include <hwy/aligned_allocator.h>
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#ifndef SG_VISION_STEREO_FAST_JOB
#define SG_VISION_STEREO_FAST_JOB
namespace sg::vision::fast_detail {
/// One tile's work. Input rows are counted from `ya` = y_begin - h (the first row a block reads).
/// Right rows are stored reversed (rev[i] = right[width - 1 - i]) so that the pixels x - d of the
/// disparities d = 0, 1, ... of one left pixel are contiguous in memory.
struct FastJob {
  int width = 0;
  int num_disp = 0;  ///< multiple of 16
  int min_disp = 0;
  int half = 0;        ///< block_size / 2
  int uniqueness = 0;  ///< percent
  int lr_max_diff = -1;
  bool census = false;
  int y_begin = 0, y_end = 0;                ///< output rows (all inside [h, height - h))
  const std::uint8_t* left8 = nullptr;       ///< SAD: prefiltered left rows
  const std::uint8_t* right8_rev = nullptr;  ///< SAD: prefiltered right rows, reversed
  size_t step8 = 0;                          ///< elements per row
  /// Census: signatures split into planes of their low 16 and high 8 bits (16-bit lanes).
  const std::uint16_t* left_lo = nullptr;
  const std::uint16_t* left_hi = nullptr;
  const std::uint16_t* right_lo_rev = nullptr;  ///< reversed like right8_rev
  const std::uint16_t* right_hi_rev = nullptr;
  size_t step16 = 0;
  const std::uint8_t* texture_ok = nullptr;  ///< per output row and x: 1 = enough texture
  size_t texture_step = 0;
  std::uint16_t* v = nullptr;   ///< scratch: column sums, (width - xb) x num_disp, aligned
  std::uint16_t* s = nullptr;   ///< scratch: block sums of one row, output columns x num_disp
  std::int16_t* out = nullptr;  ///< per output row: disparity * 16 or kInvalid16
  size_t out_step = 0;
};
}  // namespace sg::vision::fast_detail
#endif

HWY_BEFORE_NAMESPACE();
namespace sg::vision::fast_detail {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

/// Pixel costs of input row `off` (element offset of the row) for column x and the disparities
/// [d, d + Lanes(d16)): |left - right| of the prefiltered images or census Hamming distances.
template <bool kCensus, class D16>
HWY_INLINE hn::Vec<D16> CostAt(D16 d16, const FastJob& j, size_t off, int x, int d) {
  const size_t rx = off + static_cast<size_t>(j.width - 1 - x + j.min_disp + d);
  if constexpr (!kCensus) {
    const hn::Rebind<std::uint8_t, D16> d8;
    const auto lv = hn::Set(d16, j.left8[off + x]);
    const auto rv = hn::PromoteTo(d16, hn::LoadU(d8, j.right8_rev + rx));
    return hn::Sub(hn::Max(lv, rv), hn::Min(lv, rv));
  } else {
    const auto lo = hn::Xor(hn::Set(d16, j.left_lo[off + x]), hn::LoadU(d16, j.right_lo_rev + rx));
    const auto hi = hn::Xor(hn::Set(d16, j.left_hi[off + x]), hn::LoadU(d16, j.right_hi_rev + rx));
    return hn::Add(hn::PopulationCount(lo), hn::PopulationCount(hi));
  }
}

/// Column sums V[x][d] for the columns x >= xb: adds the costs of input row `add` and, when
/// sub >= 0, subtracts those of row `sub` (u16 arithmetic is exact modulo 2^16 and the true sums
/// fit in 16 bits, so the result is exact).
template <bool kCensus, class D16>
void UpdateColumns(D16 d16, const FastJob& j, int add, int sub, std::uint16_t* HWY_RESTRICT v) {
  const int n = static_cast<int>(hn::Lanes(d16));
  const int xb = j.min_disp + j.num_disp - 1, nd = j.num_disp;
  const size_t step = kCensus ? j.step16 : j.step8;
  const size_t off_add = static_cast<size_t>(add) * step;
  const size_t off_sub = static_cast<size_t>(sub < 0 ? 0 : sub) * step;
  for (int x = xb; x < j.width; ++x) {
    std::uint16_t* dst = v + static_cast<size_t>(x - xb) * nd;
    for (int d = 0; d < nd; d += n) {
      auto acc = hn::Add(hn::Load(d16, dst + d), CostAt<kCensus>(d16, j, off_add, x, d));
      if (sub >= 0) acc = hn::Sub(acc, CostAt<kCensus>(d16, j, off_sub, x, d));
      hn::Store(acc, d16, dst + d);
    }
  }
}

/// Smallest lane. On SSE4 and up: fold to 8 lanes, then PHMINPOSUW (one instruction).
template <class D16>
HWY_INLINE std::uint16_t MinLane(D16 d16, hn::Vec<D16> v) {
#if HWY_ARCH_X86 && HWY_TARGET <= HWY_SSE4
  if constexpr (hn::MaxLanes(d16) >= 8) {
    if constexpr (hn::MaxLanes(d16) == 32) {
      const hn::Half<D16> dh;
      const auto v16 = hn::Min(hn::LowerHalf(dh, v), hn::UpperHalf(dh, v));
      const hn::Half<decltype(dh)> dq;
      const auto v8 = hn::Min(hn::LowerHalf(dq, v16), hn::UpperHalf(dq, v16));
      return static_cast<std::uint16_t>(_mm_extract_epi16(_mm_minpos_epu16(v8.raw), 0));
    } else if constexpr (hn::MaxLanes(d16) == 16) {
      const hn::Half<D16> dh;
      const auto v8 = hn::Min(hn::LowerHalf(dh, v), hn::UpperHalf(dh, v));
      return static_cast<std::uint16_t>(_mm_extract_epi16(_mm_minpos_epu16(v8.raw), 0));
    } else {
      return static_cast<std::uint16_t>(_mm_extract_epi16(_mm_minpos_epu16(v.raw), 0));
    }
  }
#endif
  return hn::GetLane(hn::MinOfLanes(d16, v));
}

template <bool kCensus, class D16>
void MatchRowsT(D16 d16, const FastJob& j) {
  const int n = static_cast<int>(hn::Lanes(d16));
  const int nd = j.num_disp, h = j.half;
  const int xb = j.min_disp + nd - 1;       // first column with a full search range
  const int x0 = xb + h, x1 = j.width - h;  // output columns
  const int ncols = j.width - xb, nout = x1 - x0;
  std::uint16_t* HWY_RESTRICT v = j.v;
  std::uint16_t* HWY_RESTRICT s = j.s;
  std::vector<int> best(nout);
  std::fill(v, v + static_cast<size_t>(ncols) * nd, std::uint16_t{0});
  for (int row = 0; row < 2 * h + 1; ++row) UpdateColumns<kCensus>(d16, j, row, -1, v);

  for (int y = j.y_begin; y < j.y_end; ++y) {
    const int row = y - (j.y_begin - h);  // input row of y
    if (y > j.y_begin) UpdateColumns<kCensus>(d16, j, row + h, row - h - 1, v);
    // Horizontal box sums, incremental along x.
    std::uint16_t* s0 = s;
    for (int d = 0; d < nd; d += n) {
      auto acc = hn::Zero(d16);
      for (int k = 0; k < 2 * h + 1; ++k)
        acc = hn::Add(acc, hn::Load(d16, v + static_cast<size_t>(k) * nd + d));
      hn::Store(acc, d16, s0 + d);
    }
    for (int i = 1; i < nout; ++i) {
      const std::uint16_t* add = v + static_cast<size_t>(i + 2 * h) * nd;
      const std::uint16_t* sub = v + static_cast<size_t>(i - 1) * nd;
      const std::uint16_t* prev = s + static_cast<size_t>(i - 1) * nd;
      std::uint16_t* cur = s + static_cast<size_t>(i) * nd;
      for (int d = 0; d < nd; d += n) {
        const auto sum = hn::Sub(hn::Add(hn::Load(d16, prev + d), hn::Load(d16, add + d)),
                                 hn::Load(d16, sub + d));
        hn::Store(sum, d16, cur + d);
      }
    }
    // Winner takes all, uniqueness, texture, sub-pixel.
    std::int16_t* out = j.out + static_cast<size_t>(y - j.y_begin) * j.out_step;
    const std::uint8_t* tex = j.texture_ok + static_cast<size_t>(y - j.y_begin) * j.texture_step;
    for (int i = 0; i < nout; ++i) {
      out[x0 + i] = kInvalid16;
      if (!tex[x0 + i]) continue;
      const std::uint16_t* c = s + static_cast<size_t>(i) * nd;
      auto vmin = hn::Load(d16, c);
      for (int d = n; d < nd; d += n) vmin = hn::Min(vmin, hn::Load(d16, c + d));
      const std::uint16_t m = MinLane(d16, vmin);
      const auto vm = hn::Set(d16, m);
      int b = -1;
      size_t count = 0;  // disparities within the uniqueness threshold
      const int thresh = j.uniqueness > 0 ? std::min(m + m * j.uniqueness / 100, 65535) : -1;
      const auto vt = hn::Set(d16, static_cast<std::uint16_t>(std::max(thresh, 0)));
      // Branch-free over the (few) vectors: which vector holds the winner is unpredictable.
      for (int d = 0; d < nd; d += n) {
        const auto cv = hn::Load(d16, c + d);
        const intptr_t f = hn::FindFirstTrue(d16, hn::Eq(cv, vm));
        b = (b < 0 && f >= 0) ? d + static_cast<int>(f) : b;
        if (thresh >= 0) count += hn::CountTrue(d16, hn::Eq(hn::Min(cv, vt), cv));
      }
      best[i] = b;
      if (thresh >= 0) {
        for (int d = std::max(b - 1, 0); d <= std::min(b + 1, nd - 1); ++d)
          count -= c[d] <= thresh ? 1 : 0;
        if (count != 0) continue;
      }
      const int d16v =
          (b > 0 && b < nd - 1) ? subpixel_disparity16(b, c[b - 1], c[b], c[b + 1]) : b * 16;
      out[x0 + i] = static_cast<std::int16_t>(d16v + j.min_disp * 16);
    }
    if (j.lr_max_diff >= 0) {
      // Right image's winners: right pixel xr is seen by left pixel xr + min_disp + d at d.
      std::vector<int> rbest(j.width, -1), rcost(j.width, INT_MAX);
      for (int i = 0; i < nout; ++i) {
        const std::uint16_t* c = s + static_cast<size_t>(i) * nd;
        const int x = x0 + i;
        for (int d = 0; d < nd; ++d) {
          const int xr = x - j.min_disp - d;
          if (c[d] < rcost[xr] || (c[d] == rcost[xr] && d < rbest[xr])) {
            rcost[xr] = c[d];
            rbest[xr] = d;
          }
        }
      }
      for (int i = 0; i < nout; ++i) {
        if (out[x0 + i] == kInvalid16) continue;
        const int xr = x0 + i - j.min_disp - best[i];
        if (std::abs(rbest[xr] - best[i]) > j.lr_max_diff) out[x0 + i] = kInvalid16;
      }
    }
  }
}

/// Full-width vectors when the range is a whole number of them (AVX-512: 32 lanes), else at
/// most 16 lanes, which every multiple of 16 disparities fills.
void MatchRows(const FastJob& j) {
  const hn::ScalableTag<std::uint16_t> full;
  const hn::CappedTag<std::uint16_t, 16> capped;
  const bool use_full = j.num_disp % static_cast<int>(hn::Lanes(full)) == 0;
  if (j.census) {
    if (use_full)
      MatchRowsT<true>(full, j);
    else
      MatchRowsT<true>(capped, j);
  } else {
    if (use_full)
      MatchRowsT<false>(full, j);
    else
      MatchRowsT<false>(capped, j);
  }
}

std::int64_t CurrentTarget() { return HWY_TARGET; }

}  // namespace HWY_NAMESPACE
}  // namespace sg::vision::fast_detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sg::vision {
namespace fast_detail {
HWY_EXPORT(MatchRows);
HWY_EXPORT(CurrentTarget);

namespace {
/// Copies each row of `rows` (elements of type T) through `f` into the continuous buffer `out`,
/// reversed when `reverse`.
template <typename Out, typename T, typename F>
void plane(const cv::Mat& rows, bool reverse, F f, std::vector<Out>& out) {
  const int w = rows.cols;
  out.resize(static_cast<size_t>(rows.rows) * w);
  for (int y = 0; y < rows.rows; ++y) {
    const T* src = rows.ptr<T>(y);
    Out* dst = out.data() + static_cast<size_t>(y) * w;
    for (int x = 0; x < w; ++x) dst[reverse ? w - 1 - x : x] = f(src[x]);
  }
}

/// Buffers reused across calls on one thread: allocating megabytes per frame costs page faults.
/// They hold no state that reaches the output.
struct Scratch {
  cv::Mat pl, pr, cl, cr, integral, tex_ok, out16;
  std::vector<std::uint8_t> r8;
  std::vector<std::uint16_t> llo, lhi, rlo, rhi;
  hwy::AlignedFreeUniquePtr<std::uint16_t[]> v, s;
  size_t v_size = 0, s_size = 0;
};

std::uint16_t* aligned(hwy::AlignedFreeUniquePtr<std::uint16_t[]>& p, size_t& size, size_t need) {
  if (size < need) {
    p = hwy::AllocateAligned<std::uint16_t>(need);
    size = need;
  }
  return p.get();
}
}  // namespace
}  // namespace fast_detail

std::string fast_matcher_target() {
  return hwy::TargetName(HWY_DYNAMIC_DISPATCH(fast_detail::CurrentTarget)());
}

void match_fast_rows(const cv::Mat& left, const cv::Mat& right, const core::BmParams& p,
                     cv::Mat& disp, cv::Range rows) {
  using namespace fast_detail;
  const int height = left.rows, width = left.cols;
  if (rows == cv::Range::all()) rows = cv::Range(0, height);
  disp.create(left.size(), CV_32F);
  if (rows.empty()) return;
  disp.rowRange(rows).setTo(-1.0f);
  const int nd = p.num_disparities, md = p.min_disparity, h = p.block_size / 2;
  const int y0 = std::max(rows.start, h), y1 = std::min(rows.end, height - h);
  if (y0 >= y1 || md + nd - 1 + h >= width - h) return;
  const int ya = y0 - h, yb = y1 + h;  // input rows the blocks read

  FastJob job;
  job.width = width;
  job.num_disp = nd;
  job.min_disp = md;
  job.half = h;
  job.uniqueness = p.uniqueness_ratio;
  job.lr_max_diff = p.lr_max_diff;
  job.census = p.cost == core::MatchCost::kCensus;
  job.y_begin = y0;
  job.y_end = y1;

  thread_local Scratch scratch;
  Scratch& sc = scratch;
  cv::Mat &pl = sc.pl, &pr = sc.pr, &cl = sc.cl, &cr = sc.cr;
  prefilter_rows(left, p.prefilter_cap, ya, yb, pl);  // SAD cost and texture
  if (!job.census) {
    prefilter_rows(right, p.prefilter_cap, ya, yb, pr);
    const auto same = [](std::uint8_t v) { return v; };
    plane<std::uint8_t, std::uint8_t>(pr, true, same, sc.r8);
    job.step8 = static_cast<size_t>(width);  // pl is continuous: created above
    job.left8 = pl.ptr<std::uint8_t>(0);
    job.right8_rev = sc.r8.data();
  } else {
    census_rows(left, ya, yb, cl);
    census_rows(right, ya, yb, cr);
    const auto lo = [](int v) { return static_cast<std::uint16_t>(v & 0xFFFF); };
    const auto hi = [](int v) { return static_cast<std::uint16_t>(v >> 16); };
    plane<std::uint16_t, int>(cl, false, lo, sc.llo);
    plane<std::uint16_t, int>(cl, false, hi, sc.lhi);
    plane<std::uint16_t, int>(cr, true, lo, sc.rlo);
    plane<std::uint16_t, int>(cr, true, hi, sc.rhi);
    job.step16 = static_cast<size_t>(width);
    job.left_lo = sc.llo.data();
    job.left_hi = sc.lhi.data();
    job.right_lo_rev = sc.rlo.data();
    job.right_hi_rev = sc.rhi.data();
  }

  // Texture: block sums of |prefiltered - cap| from an integral image (exact integers).
  cv::Mat& integral = sc.integral;
  integral.create(pl.rows + 1, width + 1, CV_32S);
  integral.row(0).setTo(0);
  for (int y = 0; y < pl.rows; ++y) {
    const std::uint8_t* src = pl.ptr<std::uint8_t>(y);
    const int* above = integral.ptr<int>(y);
    int* dst = integral.ptr<int>(y + 1);
    dst[0] = 0;
    int row_sum = 0;
    for (int x = 0; x < width; ++x) {
      row_sum += std::abs(src[x] - p.prefilter_cap);
      dst[x + 1] = above[x + 1] + row_sum;
    }
  }
  cv::Mat& tex_ok = sc.tex_ok;
  tex_ok.create(y1 - y0, width, CV_8U);
  tex_ok.setTo(0);
  const int b = 2 * h + 1;
  for (int y = y0; y < y1; ++y) {
    const int* top = integral.ptr<int>(y - h - ya);
    const int* bottom = integral.ptr<int>(y - h - ya + b);
    std::uint8_t* ok = tex_ok.ptr<std::uint8_t>(y - y0);
    for (int x = h; x < width - h; ++x) {
      const int sum = bottom[x + h + 1] - bottom[x - h] - top[x + h + 1] + top[x - h];
      ok[x] = sum >= p.texture_threshold ? 1 : 0;
    }
  }
  job.texture_ok = tex_ok.ptr<std::uint8_t>(0);
  job.texture_step = tex_ok.step1();

  cv::Mat& out16 = sc.out16;
  out16.create(y1 - y0, width, CV_16S);
  out16.setTo(kInvalid16);
  const int xb = md + nd - 1;
  job.v = aligned(sc.v, sc.v_size, static_cast<size_t>(width - xb) * nd);
  job.s = aligned(sc.s, sc.s_size, static_cast<size_t>(width - h - (xb + h)) * nd);
  job.out = out16.ptr<std::int16_t>(0);
  job.out_step = out16.step1();
  HWY_DYNAMIC_DISPATCH(MatchRows)(job);
  store_disparity16(out16, y0, disp);
}

}  // namespace sg::vision
#endif  // HWY_ONCE
