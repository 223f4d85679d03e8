// The fast matcher's SIMD kernel (Google Highway, compiled once per x86 target and dispatched at
// run time) and its driver. The scalar reference is stereo_fast_reference.cpp.
#include "sg/vision/stereo_fast.hpp"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cstring>
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
  std::uint16_t* v = nullptr;        ///< scratch: column sums, (width - xb) x num_disp, aligned
  std::uint16_t* s = nullptr;        ///< scratch: block sums of one row, output columns x num_disp
  std::uint16_t* sacc = nullptr;     ///< scratch: running horizontal sums, num_disp, aligned
  std::uint16_t* mins = nullptr;     ///< scratch: per output column of a row, smallest sum
  std::uint16_t* threshs = nullptr;  ///< scratch: per output column of a row, uniqueness bound
  std::int32_t* fit = nullptr;       ///< scratch: 5 x output columns, sub-pixel fit inputs
  std::int16_t* out = nullptr;       ///< per output row: disparity * 16 or kInvalid16
  size_t out_step = 0;
};
}  // namespace sg::vision::fast_detail
#endif

HWY_BEFORE_NAMESPACE();
namespace sg::vision::fast_detail {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

/// One input row's pixels as the column updates read them. The right rows are offset so that
/// r[-x + d] is the right pixel matched with left pixel x at disparity min_disp + d.
struct RowPtrs {
  const std::uint8_t* l8 = nullptr;
  const std::uint8_t* r8 = nullptr;
  const std::uint16_t *llo = nullptr, *lhi = nullptr, *rlo = nullptr, *rhi = nullptr;
};

HWY_INLINE RowPtrs RowAt(const FastJob& j, int row) {
  RowPtrs p;
  const ptrdiff_t rx = j.width - 1 + j.min_disp;
  if (j.census) {
    const size_t off = static_cast<size_t>(row) * j.step16;
    p.llo = j.left_lo + off;
    p.lhi = j.left_hi + off;
    p.rlo = j.right_lo_rev + off + rx;
    p.rhi = j.right_hi_rev + off + rx;
  } else {
    const size_t off = static_cast<size_t>(row) * j.step8;
    p.l8 = j.left8 + off;
    p.r8 = j.right8_rev + off + rx;
  }
  return p;
}

/// Pixel costs of left pixel x at the disparities [d, d + Lanes(d16)) of one row: |left - right|
/// of the prefiltered images or census Hamming distances. `lv`, `lhi`: left pixel broadcast.
template <bool kCensus, class D16>
HWY_INLINE hn::Vec<D16> CostAt(D16 d16, const RowPtrs& p, hn::Vec<D16> lv, hn::Vec<D16> lhi, int x,
                               int d) {
  if constexpr (!kCensus) {
    const hn::Rebind<std::uint8_t, D16> d8;
    const auto rv = hn::PromoteTo(d16, hn::LoadU(d8, p.r8 - x + d));
    return hn::Sub(hn::Max(lv, rv), hn::Min(lv, rv));
  } else {
    const auto lo = hn::Xor(lv, hn::LoadU(d16, p.rlo - x + d));
    const auto hi = hn::Xor(lhi, hn::LoadU(d16, p.rhi - x + d));
    return hn::Add(hn::PopulationCount(lo), hn::PopulationCount(hi));
  }
}

/// Column x of the column sums V[x][d] (`col`): adds the costs of row `a` and, when kSub,
/// subtracts those of row `s` (u16 arithmetic is exact modulo 2^16 and the true sums fit in 16
/// bits, so the result is exact). kNV: vectors per disparity range, 0 = nd / Lanes at run time.
template <bool kCensus, bool kSub, int kNV, class D16>
HWY_INLINE void UpdateColumn(D16 d16, const RowPtrs& a, const RowPtrs& s, int x, int nd,
                             std::uint16_t* HWY_RESTRICT col) {
  const int n = static_cast<int>(hn::Lanes(d16));
  hn::Vec<D16> la, ha, ls, hs;
  if constexpr (kCensus) {
    la = hn::Set(d16, a.llo[x]);
    ha = hn::Set(d16, a.lhi[x]);
    if constexpr (kSub) {
      ls = hn::Set(d16, s.llo[x]);
      hs = hn::Set(d16, s.lhi[x]);
    }
  } else {
    la = hn::Set(d16, a.l8[x]);
    ha = la;
    if constexpr (kSub) {
      ls = hn::Set(d16, s.l8[x]);
      hs = ls;
    }
  }
  const int end = kNV > 0 ? kNV * n : nd;
#if HWY_TARGET != HWY_SCALAR
  if constexpr (!kCensus && kSub && kNV > 0 && kNV % 2 == 0 && hn::MaxLanes(d16) >= 8) {
    // Two vectors at once from full-width u8 vectors: |l - r| of both rows in u8, their
    // difference in i8 (both are at most 2 * 63), widened and added.
    const hn::Repartition<std::uint8_t, D16> d8;
    const hn::Repartition<std::int8_t, D16> di8;
    const hn::Half<decltype(di8)> dh8;
    const hn::Repartition<std::int16_t, D16> di16;
    const auto l8a = hn::Set(d8, a.l8[x]), l8s = hn::Set(d8, s.l8[x]);
    for (int d = 0; d < end; d += 2 * n) {
      const auto ra8 = hn::LoadU(d8, a.r8 - x + d), rs8 = hn::LoadU(d8, s.r8 - x + d);
      const auto da = hn::Sub(hn::Max(l8a, ra8), hn::Min(l8a, ra8));
      const auto ds = hn::Sub(hn::Max(l8s, rs8), hn::Min(l8s, rs8));
      const auto delta = hn::BitCast(di8, hn::Sub(da, ds));
      const auto lo = hn::BitCast(d16, hn::PromoteTo(di16, hn::LowerHalf(dh8, delta)));
      const auto hi = hn::BitCast(d16, hn::PromoteTo(di16, hn::UpperHalf(dh8, delta)));
      hn::Store(hn::Add(hn::Load(d16, col + d), lo), d16, col + d);
      hn::Store(hn::Add(hn::Load(d16, col + d + n), hi), d16, col + d + n);
    }
    return;
  }
#endif
  for (int d = 0; d < end; d += n) {
    auto acc = hn::Add(hn::Load(d16, col + d), CostAt<kCensus>(d16, a, la, ha, x, d));
    if constexpr (kSub) acc = hn::Sub(acc, CostAt<kCensus>(d16, s, ls, hs, x, d));
    hn::Store(acc, d16, col + d);
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

/// Lane i of the mask as bit i (at most 64 lanes).
template <class D16>
HWY_INLINE std::uint64_t MaskBits(D16 d16, hn::Mask<D16> m) {
#if HWY_TARGET <= HWY_AVX3
  (void)d16;
  return static_cast<std::uint64_t>(m.raw);
#else
  std::uint8_t bytes[8] = {};
  hn::StoreMaskBits(d16, m, bytes);
  std::uint64_t bits = 0;
  std::memcpy(&bits, bytes, sizeof(bits));
  return bits;
#endif
}

/// Bit p of 64-bit word w of a bitmap (0 when p is in another word or negative).
HWY_INLINE std::uint64_t BitIn(int w, int p) {
  return (p >> 6) == w ? std::uint64_t{1} << (p & 63) : 0;
}

/// One row's block sums, winners and checks, in three passes over its output pixels. 1: the
/// newest column of V is updated (when kSub: the row moved down by one) and added to the running
/// horizontal sums S, which are stored (j.s) with their minimum, then lose their oldest column.
/// 2: winner and uniqueness from lane masks. 3: sub-pixel fits, vectorised. Separate passes let
/// the core overlap pixels instead of waiting on each one's reduction chain. kNV: vectors per
/// disparity range, S in registers and 64-bit masks; 0 = any range, S in memory, reduced vector
/// by vector.
template <bool kCensus, bool kSub, int kNV, class D16>
void MatchRow(D16 d16, const FastJob& j, int y, int* HWY_RESTRICT best) {
  constexpr int kMaxNV = kNV > 0 ? kNV : 1;
  const int n = static_cast<int>(hn::Lanes(d16));
  const int nd = j.num_disp, h = j.half, nv = kNV > 0 ? kNV : nd / n;
  const int xb = j.min_disp + nd - 1;  // first column with a full search range
  const int x0 = xb + h, nout = j.width - h - x0;
  const int row = y - (j.y_begin - h);  // input row of y
  const RowPtrs ra = RowAt(j, row + h), rs = RowAt(j, kSub ? row - h - 1 : 0);
  std::uint16_t* HWY_RESTRICT v = j.v;
  std::uint16_t* HWY_RESTRICT sacc = j.sacc;  // S when kNV == 0, nd lanes
  const int u = j.uniqueness;

  hn::Vec<D16> sr[kMaxNV];  // S when kNV > 0
  for (int k = 0; k < kMaxNV; ++k) sr[k] = hn::Zero(d16);
  if constexpr (kNV == 0) std::fill(sacc, sacc + nd, std::uint16_t{0});
  for (int c = 0; c < 2 * h; ++c) {
    std::uint16_t* col = v + static_cast<size_t>(c) * nd;
    if constexpr (kSub) UpdateColumn<kCensus, true, kNV>(d16, ra, rs, xb + c, nd, col);
    for (int k = 0; k < nv; ++k) {
      if constexpr (kNV > 0) {
        sr[k] = hn::Add(sr[k], hn::Load(d16, col + k * n));
      } else {
        hn::Store(hn::Add(hn::Load(d16, sacc + k * n), hn::Load(d16, col + k * n)), d16,
                  sacc + k * n);
      }
    }
  }

  std::int16_t* HWY_RESTRICT out = j.out + static_cast<size_t>(y - j.y_begin) * j.out_step + x0;
  const std::uint8_t* HWY_RESTRICT tex =
      j.texture_ok + static_cast<size_t>(y - j.y_begin) * j.texture_step + x0;
  std::uint16_t* HWY_RESTRICT s = j.s;
  std::uint16_t* HWY_RESTRICT mins = j.mins;
  std::uint16_t* HWY_RESTRICT threshs = j.threshs;
  std::int32_t* HWY_RESTRICT fb = j.fit;      // per output column: winner, its neighbours' and own
  std::int32_t* HWY_RESTRICT fm = fb + nout;  // sums, valid flag
  std::int32_t* HWY_RESTRICT fp = fm + nout;
  std::int32_t* HWY_RESTRICT f0 = fp + nout;
  std::int32_t* HWY_RESTRICT fok = f0 + nout;
  // Pass 1: block sums of every pixel of the row (kept in s) and their minimum. Nothing here
  // waits on a reduction, so consecutive pixels overlap in the core.
  for (int i = 0; i < nout; ++i) {
    std::uint16_t* HWY_RESTRICT col = v + static_cast<size_t>(i + 2 * h) * nd;
    if constexpr (kSub) UpdateColumn<kCensus, true, kNV>(d16, ra, rs, xb + i + 2 * h, nd, col);
    std::uint16_t* HWY_RESTRICT c = s + static_cast<size_t>(i) * nd;
    auto vmin = hn::Set(d16, std::uint16_t{0xFFFF});
    for (int k = 0; k < nv; ++k) {
      hn::Vec<D16> sk;
      if constexpr (kNV > 0) {
        sr[k] = hn::Add(sr[k], hn::Load(d16, col + k * n));
        sk = sr[k];
      } else {
        sk = hn::Add(hn::Load(d16, sacc + k * n), hn::Load(d16, col + k * n));
      }
      hn::Store(sk, d16, c + k * n);
      vmin = hn::Min(vmin, sk);
    }
    mins[i] = MinLane(d16, vmin);
    // The oldest column leaves the window.
    const std::uint16_t* HWY_RESTRICT old = v + static_cast<size_t>(i) * nd;
    for (int k = 0; k < nv; ++k) {
      if constexpr (kNV > 0) {
        sr[k] = hn::Sub(sr[k], hn::Load(d16, old + k * n));
      } else {
        hn::Store(hn::Sub(hn::Add(hn::Load(d16, sacc + k * n), hn::Load(d16, col + k * n)),
                          hn::Load(d16, old + k * n)),
                  d16, sacc + k * n);
      }
    }
  }
  // Uniqueness thresholds of the row (a loop the compiler vectorises).
  for (int i = 0; i < nout; ++i) {
    const int m = mins[i];
    threshs[i] = static_cast<std::uint16_t>(u > 0 ? std::min(m + m * u / 100, 65535) : 0);
  }
  // Pass 2: winner: the largest disparity with the smallest sum (StereoBM's choice on ties; the
  // nearer surface, the cautious one for obstacle warning). Uniqueness: no disparity further than
  // 1 px from it at or below the threshold. Branch-free: where the winner is is unpredictable.
  const int min16 = j.min_disp * 16;
  for (int i = 0; i < nout; ++i) {
    const std::uint16_t* HWY_RESTRICT c = s + static_cast<size_t>(i) * nd;
    const int m = mins[i], thresh = threshs[i];
    const auto vm = hn::Set(d16, mins[i]);
    const auto vt = hn::Set(d16, threshs[i]);
    int b = 0;
    bool unique = true;
    if constexpr (kNV > 0) {
      constexpr int kWords = (kNV * hn::MaxLanes(d16) + 63) / 64;
      std::uint64_t eq[kWords] = {}, le[kWords] = {};
      for (int k = 0; k < kNV; ++k) {
        const int w = k * n / 64, sh = k * n % 64;
        const auto sk = hn::Load(d16, c + k * n);
        eq[w] |= MaskBits(d16, hn::Eq(sk, vm)) << sh;
        le[w] |= MaskBits(d16, hn::Eq(hn::Min(sk, vt), sk)) << sh;  // sum <= thresh
      }
      for (int w = 0; w < kWords; ++w)  // the last (largest) disparity with the minimum
        b = eq[w] != 0 ? w * 64 + 63 - static_cast<int>(hwy::Num0BitsAboveMS1Bit_Nonzero64(eq[w]))
                       : b;
      std::uint64_t far = 0;
      if constexpr (kWords == 1) {
        far = le[0] & ~(b > 0 ? std::uint64_t{7} << (b - 1) : std::uint64_t{3});
      } else {
        for (int w = 0; w < kWords; ++w)
          far |= le[w] & ~(BitIn(w, b - 1) | BitIn(w, b) | BitIn(w, b + 1));
      }
      unique = far == 0;
    } else {
      size_t count = 0;
      for (int k = 0; k < nv; ++k) {
        const auto sk = hn::Load(d16, c + k * n);
        const std::uint64_t bits = MaskBits(d16, hn::Eq(sk, vm));
        b = bits != 0 ? k * n + 63 - static_cast<int>(hwy::Num0BitsAboveMS1Bit_Nonzero64(bits)) : b;
        count += hn::CountTrue(d16, hn::Eq(hn::Min(sk, vt), sk));  // sum <= thresh
      }
      const int cm = c[b > 0 ? b - 1 : 0], cp = c[b < nd - 1 ? b + 1 : nd - 1];
      const size_t near = 1 + static_cast<size_t>(b > 0 && cm <= thresh) +
                          static_cast<size_t>(b < nd - 1 && cp <= thresh);
      unique = count == near;
    }
    fb[i] = b;
    fm[i] = c[b > 0 ? b - 1 : 0];
    fp[i] = c[b < nd - 1 ? b + 1 : nd - 1];
    f0[i] = m;
    fok[i] = (tex[i] != 0 && (u <= 0 || unique)) ? 1 : 0;
    best[i] = b;
  }
  // Pass 3: sub-pixel fits of the row, vectorised: subpixel_disparity16's truncating division is
  // done in doubles, which is exact here (|quotient| <= 256 with a numerator below 2^24 and a
  // denominator below 2^18: a non-integer quotient lies >= 2^-18 from an integer, far more than
  // a double's rounding error, and an integer one is exact).
  const hn::ScalableTag<double> dd;
  const hn::Rebind<std::int32_t, decltype(dd)> di;
  const hn::Rebind<std::int16_t, decltype(dd)> dw;
  const int nf = static_cast<int>(hn::Lanes(dd));
  const auto zero = hn::Zero(di), one = hn::Set(di, 1), last = hn::Set(di, nd - 1);
  int i = 0;
  for (; i + nf <= nout; i += nf) {
    const auto b = hn::LoadU(di, fb + i), cm = hn::LoadU(di, fm + i), cp = hn::LoadU(di, fp + i);
    const auto c0 = hn::LoadU(di, f0 + i);
    const auto diff = hn::Sub(cm, cp);
    const auto denom = hn::Add(hn::Sub(hn::Add(cm, cp), hn::Add(c0, c0)), hn::Abs(diff));
    const auto q = hn::DemoteTo(di, hn::Div(hn::PromoteTo(dd, hn::ShiftLeft<8>(diff)),
                                            hn::PromoteTo(dd, hn::Max(denom, one))));
    const auto off = hn::IfThenZeroElse(hn::Eq(denom, zero), q);
    const auto fit = hn::ShiftRight<4>(hn::Add(hn::Add(hn::ShiftLeft<8>(b), off), hn::Set(di, 15)));
    const auto interior = hn::And(hn::Lt(zero, b), hn::Lt(b, last));
    auto d16v = hn::Add(hn::IfThenElse(interior, fit, hn::ShiftLeft<4>(b)), hn::Set(di, min16));
    d16v = hn::IfThenElse(hn::Eq(hn::LoadU(di, fok + i), zero),
                          hn::Set(di, static_cast<std::int32_t>(kInvalid16)), d16v);
    hn::StoreU(hn::DemoteTo(dw, d16v), dw, out + i);
  }
  for (; i < nout; ++i) {
    const int b = fb[i];
    const int d16v = (b > 0 && b < nd - 1) ? subpixel_disparity16(b, fm[i], f0[i], fp[i]) : b * 16;
    out[i] = fok[i] != 0 ? static_cast<std::int16_t>(d16v + min16) : kInvalid16;
  }
}

template <bool kCensus, int kNV, class D16>
void MatchRowsT(D16 d16, const FastJob& j) {
  const int nd = j.num_disp, h = j.half;
  const int xb = j.min_disp + nd - 1;       // first column with a full search range
  const int x0 = xb + h, x1 = j.width - h;  // output columns
  const int ncols = j.width - xb, nout = x1 - x0;
  std::uint16_t* HWY_RESTRICT v = j.v;
  std::vector<int> best(nout);
  std::vector<std::uint32_t> rkey(j.lr_max_diff >= 0 ? static_cast<size_t>(j.width) : 0);
  std::fill(v, v + static_cast<size_t>(ncols) * nd, std::uint16_t{0});
  for (int row = 0; row < 2 * h + 1; ++row) {
    const RowPtrs ra = RowAt(j, row);
    for (int c = 0; c < ncols; ++c)
      UpdateColumn<kCensus, false, kNV>(d16, ra, ra, xb + c, nd, v + static_cast<size_t>(c) * nd);
  }

  for (int y = j.y_begin; y < j.y_end; ++y) {
    if (y > j.y_begin)
      MatchRow<kCensus, true, kNV>(d16, j, y, best.data());
    else
      MatchRow<kCensus, false, kNV>(d16, j, y, best.data());
    if (j.lr_max_diff >= 0) {
      // Right image's winners: right pixel xr is seen by left pixel xr + min_disp + d at d; the
      // least cost wins, the smaller d on a tie, i.e. the least key (cost << 16 | d). For one left
      // pixel the keys of d = nd - 1 .. 0 fall on consecutive right pixels: a contiguous
      // element-wise min the compiler vectorises (the nested branchy loop cost 6.8 ms a frame).
      const std::uint16_t* s = j.s;
      std::int16_t* out = j.out + static_cast<size_t>(y - j.y_begin) * j.out_step;
      std::fill(rkey.begin(), rkey.end(), UINT32_MAX);
      for (int i = 0; i < nout; ++i) {
        const std::uint16_t* c = s + static_cast<size_t>(i) * nd;
        std::uint32_t* r = rkey.data() + (x0 + i - j.min_disp - (nd - 1));  // r[k]: d = nd-1-k
        for (int k = 0; k < nd; ++k) {
          const int d = nd - 1 - k;
          const std::uint32_t key = (std::uint32_t{c[d]} << 16) | static_cast<std::uint32_t>(d);
          r[k] = std::min(r[k], key);
        }
      }
      for (int i = 0; i < nout; ++i) {
        if (out[x0 + i] == kInvalid16) continue;
        const int xr = x0 + i - j.min_disp - best[i];
        const int rbest = static_cast<int>(rkey[static_cast<size_t>(xr)] & 0xFFFFu);
        if (std::abs(rbest - best[i]) > j.lr_max_diff) out[x0 + i] = kInvalid16;
      }
    }
  }
}

template <bool kCensus, class D16>
void MatchRowsNV(D16 d16, const FastJob& j) {
  switch (j.num_disp / static_cast<int>(hn::Lanes(d16))) {
    case 1:
      return MatchRowsT<kCensus, 1>(d16, j);
    case 2:
      return MatchRowsT<kCensus, 2>(d16, j);
    case 4:
      return MatchRowsT<kCensus, 4>(d16, j);
    case 8:
      return MatchRowsT<kCensus, 8>(d16, j);
    default:
      return MatchRowsT<kCensus, 0>(d16, j);
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
      MatchRowsNV<true>(full, j);
    else
      MatchRowsNV<true>(capped, j);
  } else {
    if (use_full)
      MatchRowsNV<false>(full, j);
    else
      MatchRowsNV<false>(capped, j);
  }
}

/// StereoBM's x-Sobel prefilter of one row (as fast_detail::prefilter_rows, which is the
/// reference): rows a, b, c are the rows above, at and below; out[0] = out[width - 1] = cap.
/// When `reverse`, the row is written reversed (out[width - 1 - x]).
void PrefilterRow(const std::uint8_t* HWY_RESTRICT a, const std::uint8_t* HWY_RESTRICT b,
                  const std::uint8_t* HWY_RESTRICT c, int width, int cap, bool reverse,
                  std::uint8_t* HWY_RESTRICT out) {
  const hn::ScalableTag<std::int16_t> di;
  const hn::Rebind<std::uint8_t, decltype(di)> d8;
  const int n = static_cast<int>(hn::Lanes(di));
  const auto vcap = hn::Set(di, static_cast<std::int16_t>(cap));
  const auto vneg = hn::Set(di, static_cast<std::int16_t>(-cap));
  const auto load = [&](const std::uint8_t* p) { return hn::PromoteTo(di, hn::LoadU(d8, p)); };
  const auto at = [&](int x) { return reverse ? width - 1 - x : x; };
  out[0] = static_cast<std::uint8_t>(cap);
  out[width - 1] = static_cast<std::uint8_t>(cap);
  int x = 1;
  for (; x + n <= width - 1; x += n) {
    const auto ga = hn::Sub(load(a + x + 1), load(a + x - 1));
    const auto gb = hn::Sub(load(b + x + 1), load(b + x - 1));
    const auto gc = hn::Sub(load(c + x + 1), load(c + x - 1));
    const auto g = hn::Add(hn::Add(ga, gc), hn::Add(gb, gb));
    auto v = hn::Add(hn::Min(hn::Max(g, vneg), vcap), vcap);
    if (reverse) {
      v = hn::Reverse(di, v);
      hn::StoreU(hn::DemoteTo(d8, v), d8, out + (width - x - n));
    } else {
      hn::StoreU(hn::DemoteTo(d8, v), d8, out + x);
    }
  }
  for (; x + 1 < width; ++x) {
    const int g = (a[x + 1] - a[x - 1]) + 2 * (b[x + 1] - b[x - 1]) + (c[x + 1] - c[x - 1]);
    out[at(x)] = static_cast<std::uint8_t>(std::clamp(g, -cap, cap) + cap);
  }
}

/// 5x5 census signatures of one row (as fast_detail::census_rows, which is the reference), split
/// into their low 16 and high 8 bits. `pad`: the 5 rows y - 2 .. y + 2 with the border replicated,
/// each width + 4 long, pixel x at index x + 2. When `reverse`, the row is written reversed.
void CensusRow(const std::uint8_t* HWY_RESTRICT pad, int width, bool reverse,
               std::uint16_t* HWY_RESTRICT lo, std::uint16_t* HWY_RESTRICT hi) {
  const hn::ScalableTag<std::uint16_t> d16;
  const hn::Rebind<std::int16_t, decltype(d16)> di;  // pixels compared as signed 16-bit
  const hn::Rebind<std::uint8_t, decltype(d16)> d8;
  const int n = static_cast<int>(hn::Lanes(d16));
  const int r = kCensusRadius, pw = width + 2 * r;
  const auto one = hn::Set(d16, std::uint16_t{1});
  int x = 0;
  for (; x + n <= width; x += n) {
    const auto centre = hn::PromoteTo(di, hn::LoadU(d8, pad + r * pw + r + x));
    auto vlo = hn::Zero(d16), vhi = hn::Zero(d16);
    int k = 0;
    for (int dy = -r; dy <= r; ++dy) {
      for (int dx = -r; dx <= r; ++dx) {
        if (dy == 0 && dx == 0) continue;
        const auto nb = hn::PromoteTo(di, hn::LoadU(d8, pad + (dy + r) * pw + r + dx + x));
        const auto bit =
            hn::And(hn::VecFromMask(d16, hn::RebindMask(d16, hn::Lt(nb, centre))), one);
        if (k < 8)
          vhi = hn::Or(hn::Add(vhi, vhi), bit);
        else
          vlo = hn::Or(hn::Add(vlo, vlo), bit);
        ++k;
      }
    }
    if (reverse) {
      hn::StoreU(hn::Reverse(d16, vlo), d16, lo + (width - x - n));
      hn::StoreU(hn::Reverse(d16, vhi), d16, hi + (width - x - n));
    } else {
      hn::StoreU(vlo, d16, lo + x);
      hn::StoreU(vhi, d16, hi + x);
    }
  }
  for (; x < width; ++x) {
    const int c = pad[r * pw + r + x];
    std::uint32_t code = 0;
    for (int dy = -r; dy <= r; ++dy)
      for (int dx = -r; dx <= r; ++dx)
        if (dy != 0 || dx != 0)
          code = (code << 1) | static_cast<std::uint32_t>(pad[(dy + r) * pw + r + dx + x] < c);
    const int at = reverse ? width - 1 - x : x;
    lo[at] = static_cast<std::uint16_t>(code & 0xFFFF);
    hi[at] = static_cast<std::uint16_t>(code >> 16);
  }
}

/// Texture column sums: sums[x] += |add[x] - cap| and, when `sub`, -= |sub[x] - cap| (u16, exact
/// modulo 2^16; the true sums fit).
void TextureColumns(const std::uint8_t* HWY_RESTRICT add, const std::uint8_t* HWY_RESTRICT sub,
                    int width, int cap, std::uint16_t* HWY_RESTRICT sums) {
  const hn::ScalableTag<std::uint16_t> d16;
  const hn::Rebind<std::uint8_t, decltype(d16)> d8;
  const int n = static_cast<int>(hn::Lanes(d16));
  const auto vcap = hn::Set(d16, static_cast<std::uint16_t>(cap));
  const auto absdiff = [&](const std::uint8_t* p) {
    const auto v = hn::PromoteTo(d16, hn::LoadU(d8, p));
    return hn::Sub(hn::Max(v, vcap), hn::Min(v, vcap));
  };
  int x = 0;
  for (; x + n <= width; x += n) {
    auto s = hn::Add(hn::LoadU(d16, sums + x), absdiff(add + x));
    if (sub != nullptr) s = hn::Sub(s, absdiff(sub + x));
    hn::StoreU(s, d16, sums + x);
  }
  for (; x < width; ++x) {
    int s = sums[x] + std::abs(add[x] - cap);
    if (sub != nullptr) s -= std::abs(sub[x] - cap);
    sums[x] = static_cast<std::uint16_t>(s);
  }
}

/// 1/16 px disparities (kInvalid16 = invalid) to px floats (invalid = -1), as store_disparity16.
void StoreRow(const std::int16_t* HWY_RESTRICT src, int width, float* HWY_RESTRICT dst) {
  const hn::ScalableTag<float> df;
  const hn::Rebind<std::int32_t, decltype(df)> di32;
  const hn::Rebind<std::int16_t, decltype(df)> di16;
  const int n = static_cast<int>(hn::Lanes(df));
  const auto inv = hn::Set(di32, static_cast<std::int32_t>(kInvalid16));
  const auto scale = hn::Set(df, 1.0f / 16.0f);  // exact: a power of two
  const auto minus1 = hn::Set(df, -1.0f);
  int x = 0;
  for (; x + n <= width; x += n) {
    const auto v = hn::PromoteTo(di32, hn::LoadU(di16, src + x));
    const auto f = hn::Mul(hn::ConvertTo(df, v), scale);
    hn::StoreU(hn::IfThenElse(hn::RebindMask(df, hn::Eq(v, inv)), minus1, f), df, dst + x);
  }
  for (; x < width; ++x) dst[x] = src[x] == kInvalid16 ? -1.0f : static_cast<float>(src[x]) / 16.0f;
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
HWY_EXPORT(PrefilterRow);
HWY_EXPORT(CensusRow);
HWY_EXPORT(TextureColumns);
HWY_EXPORT(StoreRow);

namespace {
/// Buffers reused across calls on one thread: allocating megabytes per frame costs page faults.
/// They hold no state that reaches the output.
struct Scratch {
  cv::Mat pl, tex_ok, out16;
  std::vector<std::uint8_t> r8, pad;
  std::vector<std::uint16_t> tex_cols;
  std::vector<std::uint16_t> llo, lhi, rlo, rhi;
  hwy::AlignedFreeUniquePtr<std::uint16_t[]> v, s, small;
  std::vector<std::int32_t> fit;
  size_t v_size = 0, s_size = 0, small_size = 0;
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
  cv::Mat& pl = sc.pl;
  // Prefiltered rows (SAD cost and texture), right rows reversed; SIMD, equal to prefilter_rows.
  const auto reflect = [height](int y) {
    if (height == 1) return 0;
    return y < 0 ? -y : (y >= height ? 2 * height - 2 - y : y);
  };
  const auto prefilter = [&](const cv::Mat& img, bool reverse, std::uint8_t* dst) {
    for (int y = ya; y < yb; ++y)
      if (height % 2 == 1 && y == height - 1 && height > 1)  // flat, as StereoBM
        std::fill(dst + static_cast<size_t>(y - ya) * width,
                  dst + static_cast<size_t>(y - ya + 1) * width,
                  static_cast<std::uint8_t>(p.prefilter_cap));
      else
        HWY_DYNAMIC_DISPATCH(PrefilterRow)
    (img.ptr<std::uint8_t>(reflect(y - 1)), img.ptr<std::uint8_t>(y),
     img.ptr<std::uint8_t>(reflect(y + 1)), width, p.prefilter_cap, reverse,
     dst + static_cast<size_t>(y - ya) * width);
  };
  pl.create(yb - ya, width, CV_8U);
  prefilter(left, false, pl.ptr<std::uint8_t>(0));
  if (!job.census) {
    sc.r8.resize(static_cast<size_t>(yb - ya) * width);
    prefilter(right, true, sc.r8.data());
    job.step8 = static_cast<size_t>(width);  // pl is continuous: created above
    job.left8 = pl.ptr<std::uint8_t>(0);
    job.right8_rev = sc.r8.data();
  } else {
    // Census planes (SIMD, equal to census_rows): rows padded with the replicated border.
    const int r = kCensusRadius, pw = width + 2 * r;
    std::vector<std::uint8_t>& pad = sc.pad;
    pad.resize(static_cast<size_t>(2 * r + 1) * pw);
    const auto census = [&](const cv::Mat& img, bool reverse, std::vector<std::uint16_t>& lo,
                            std::vector<std::uint16_t>& hi) {
      lo.resize(static_cast<size_t>(yb - ya) * width);
      hi.resize(lo.size());
      for (int y = ya; y < yb; ++y) {
        for (int k = -r; k <= r; ++k) {
          const std::uint8_t* src = img.ptr<std::uint8_t>(std::clamp(y + k, 0, height - 1));
          std::uint8_t* dst = pad.data() + static_cast<size_t>(k + r) * pw;
          std::memcpy(dst + r, src, width);
          for (int i = 0; i < r; ++i) {
            dst[i] = src[0];
            dst[r + width + i] = src[width - 1];
          }
        }
        const size_t off = static_cast<size_t>(y - ya) * width;
        HWY_DYNAMIC_DISPATCH(CensusRow)
        (pad.data(), width, reverse, lo.data() + off, hi.data() + off);
      }
    };
    census(left, false, sc.llo, sc.lhi);
    census(right, true, sc.rlo, sc.rhi);
    job.step16 = static_cast<size_t>(width);
    job.left_lo = sc.llo.data();
    job.left_hi = sc.lhi.data();
    job.right_lo_rev = sc.rlo.data();
    job.right_hi_rev = sc.rhi.data();
  }

  // Texture: block sums of |prefiltered - cap|, column sums moved down row by row, then a running
  // sum along the row (exact integers).
  cv::Mat& tex_ok = sc.tex_ok;
  tex_ok.create(y1 - y0, width, CV_8U);
  tex_ok.setTo(0);
  const int b = 2 * h + 1;
  sc.tex_cols.assign(width, 0);
  std::uint16_t* cols = sc.tex_cols.data();
  for (int r = 0; r < b; ++r) HWY_DYNAMIC_DISPATCH(TextureColumns)
  (pl.ptr<std::uint8_t>(r), nullptr, width, p.prefilter_cap, cols);
  for (int y = y0; y < y1; ++y) {
    if (y > y0) HWY_DYNAMIC_DISPATCH(TextureColumns)
    (pl.ptr<std::uint8_t>(y + h - ya), pl.ptr<std::uint8_t>(y - h - 1 - ya), width, p.prefilter_cap,
     cols);
    std::uint8_t* ok = tex_ok.ptr<std::uint8_t>(y - y0);
    int sum = 0;
    for (int x = 0; x < 2 * h; ++x) sum += cols[x];
    for (int x = h; x < width - h; ++x) {
      sum += cols[x + h];
      ok[x] = sum >= p.texture_threshold ? 1 : 0;
      sum -= cols[x - h];
    }
  }
  job.texture_ok = tex_ok.ptr<std::uint8_t>(0);
  job.texture_step = tex_ok.step1();

  cv::Mat& out16 = sc.out16;
  out16.create(y1 - y0, width, CV_16S);
  out16.setTo(kInvalid16);
  const int xb = md + nd - 1;
  job.v = aligned(sc.v, sc.v_size, static_cast<size_t>(width - xb) * nd);
  const size_t nout = static_cast<size_t>(width - h - (xb + h));
  job.s = aligned(sc.s, sc.s_size, nout * nd);
  job.sacc = aligned(sc.small, sc.small_size, static_cast<size_t>(nd) + 2 * nout + 64);
  job.mins = job.sacc + nd;
  job.threshs = job.mins + nout;
  sc.fit.resize(5 * nout);
  job.fit = sc.fit.data();
  job.out = out16.ptr<std::int16_t>(0);
  job.out_step = out16.step1();
  HWY_DYNAMIC_DISPATCH(MatchRows)(job);
  for (int y = y0; y < y1; ++y)
    HWY_DYNAMIC_DISPATCH(StoreRow)(out16.ptr<std::int16_t>(y - y0), width, disp.ptr<float>(y));
}

}  // namespace sg::vision
#endif  // HWY_ONCE
