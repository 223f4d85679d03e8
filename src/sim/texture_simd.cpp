// texture_values: texture_value (sg/sim/texture.hpp) over many points, a SIMD kernel (Google
// Highway, compiled once per x86 target and dispatched at run time) and the scalar reference for
// the tail. This file is compiled with -ffp-contract=off (CMakeLists.txt): a fused multiply-add
// rounds once where the reference rounds twice, and the kernel must equal the reference bit for
// bit.
#include <cstdint>

#include "sg/sim/texture.hpp"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "src/sim/texture_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace sg::sim::texture_detail {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

/// hash_u32, lane by lane.
template <class DU, class VU>
VU HashLanes(DU du, VU h) {
  h = hn::Xor(h, hn::ShiftRight<16>(h));
  h = hn::Mul(h, hn::Set(du, 0x7feb352dU));
  h = hn::Xor(h, hn::ShiftRight<15>(h));
  h = hn::Mul(h, hn::Set(du, 0x846ca68bU));
  return hn::Xor(h, hn::ShiftRight<16>(h));
}

/// smooth(a) = a a (3 - 2 a) of texture_value, in the same order.
template <class DD, class VD>
VD SmoothLanes(DD dd, VD a) {
  return hn::Mul(hn::Mul(a, a), hn::Sub(hn::Set(dd, 3.0), hn::Mul(hn::Set(dd, 2.0), a)));
}

/// floor(x) mod 256 as an unsigned lane (the low 8 bits of the reference's int64 floor), and
/// x - floor(x). Exact for |x| < 2^53.
template <class DD, class DU, class VD>
hn::Vec<DU> FloorLanes(DD dd, DU du, VD x, VD& fraction) {
  const hn::Rebind<std::int32_t, DD> di;
  const auto whole = hn::Floor(x);
  fraction = hn::Sub(x, whole);
  const auto k256 = hn::Set(dd, 256.0);
  const auto low = hn::Sub(whole, hn::Mul(k256, hn::Floor(hn::Div(whole, k256))));
  return hn::BitCast(du, hn::DemoteTo(di, low));
}

/// Whole vectors of texture_values from 0; returns where the scalar tail starts. The operations
/// are those of texture_value, lane by lane, in the same order; an octave a lane leaves out (its
/// pixels per cell at most fade_in_px, or at least gone_px) leaves the lane's sum as it was.
int TextureVectors(const double* u, const double* v, const std::uint32_t* seed,
                   const double* footprint_m, int n, double* out) {
  const hn::ScalableTag<double> dd;
  const hn::Rebind<float, decltype(dd)> df;
  const hn::Rebind<std::uint32_t, decltype(dd)> du;
  const hn::Rebind<std::int32_t, decltype(dd)> di;
  const int lanes = static_cast<int>(hn::Lanes(dd));
  const TextureParams p;
  const float* lattice = random_lattice();
  const auto one = hn::Set(dd, 1.0);
  const auto fade_in = hn::Set(dd, p.fade_in_px), full_in = hn::Set(dd, p.full_in_px);
  const auto fade_out = hn::Set(dd, p.fade_out_px), gone = hn::Set(dd, p.gone_px);
  const auto fade_in_span = hn::Set(dd, p.full_in_px - p.fade_in_px);
  const auto fade_out_span = hn::Set(dd, p.gone_px - p.fade_out_px);
  const auto mask8 = hn::Set(du, kLatticeMask);
  const auto one_u = hn::Set(du, 1U);
  int i = 0;
  for (; i + lanes <= n; i += lanes) {
    const auto uu = hn::LoadU(dd, u + i), vv = hn::LoadU(dd, v + i);
    const auto seeds = hn::LoadU(du, seed + i);
    const auto inv_footprint = hn::Div(one, hn::LoadU(dd, footprint_m + i));
    auto sum = hn::Zero(dd);
    double cell = p.finest_cell_m;
    double inv_cell = 1.0 / p.finest_cell_m;
    for (int k = 0; k < p.octaves; ++k, cell *= 2.0, inv_cell *= 0.5) {
      const auto r = hn::Mul(hn::Set(dd, cell), inv_footprint);  // pixels per cell
      // The reference's "continue" and "break" (r only grows with k); written as negations so
      // that a NaN lane counts as present, as it does there.
      const auto gone_now = hn::Ge(r, gone);
      const auto present = hn::Not(hn::Or(hn::Le(r, fade_in), gone_now));
      if (hn::AllTrue(dd, gone_now)) break;
      if (hn::AllFalse(dd, present)) continue;
      auto w = hn::IfThenElse(hn::Lt(r, full_in),
                              SmoothLanes(dd, hn::Div(hn::Sub(r, fade_in), fade_in_span)), one);
      w = hn::IfThenElse(
          hn::Gt(r, fade_out),
          hn::Mul(w, hn::Sub(one, SmoothLanes(dd, hn::Div(hn::Sub(r, fade_out), fade_out_span)))),
          w);
      const auto s = HashLanes(
          du, hn::Add(seeds, hn::Set(du, static_cast<std::uint32_t>(k) * 0x9e3779b9U)));
      const auto x = hn::Mul(uu, hn::Set(dd, inv_cell)), y = hn::Mul(vv, hn::Set(dd, inv_cell));
      hn::Vec<decltype(dd)> fx, fy;
      const auto jx = FloorLanes(dd, du, x, fx), jy = FloorLanes(dd, du, y, fy);
      const auto a = hn::DemoteTo(df, SmoothLanes(dd, fx));
      const auto b = hn::DemoteTo(df, SmoothLanes(dd, fy));
      const auto ix = hn::Add(jx, s);
      const auto iy = hn::Add(jy, hn::ShiftRight<16>(s));
      const auto r0 = hn::ShiftLeft<kLatticeBits>(hn::And(iy, mask8));
      const auto r1 = hn::ShiftLeft<kLatticeBits>(hn::And(hn::Add(iy, one_u), mask8));
      const auto c0 = hn::And(ix, mask8), c1 = hn::And(hn::Add(ix, one_u), mask8);
      const auto n00 = hn::GatherIndex(df, lattice, hn::BitCast(di, hn::Or(r0, c0)));
      const auto n10 = hn::GatherIndex(df, lattice, hn::BitCast(di, hn::Or(r0, c1)));
      const auto n01 = hn::GatherIndex(df, lattice, hn::BitCast(di, hn::Or(r1, c0)));
      const auto n11 = hn::GatherIndex(df, lattice, hn::BitCast(di, hn::Or(r1, c1)));
      const auto top = hn::Add(n00, hn::Mul(a, hn::Sub(n10, n00)));
      const auto bottom = hn::Add(n01, hn::Mul(a, hn::Sub(n11, n01)));
      const auto value = hn::PromoteTo(dd, hn::Add(top, hn::Mul(b, hn::Sub(bottom, top))));
      sum = hn::IfThenElse(present, hn::Add(sum, hn::Mul(w, value)), sum);
    }
    hn::StoreU(hn::Mul(sum, hn::Set(dd, 1.0 / 3.6)), dd, out + i);
  }
  return i;
}

std::int64_t CurrentTarget() { return HWY_TARGET; }

}  // namespace HWY_NAMESPACE
}  // namespace sg::sim::texture_detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sg::sim {
namespace texture_detail {
HWY_EXPORT(TextureVectors);
HWY_EXPORT(CurrentTarget);
}  // namespace texture_detail

void texture_values(const double* u, const double* v, const std::uint32_t* seed,
                    const double* footprint_m, int n, double* out) {
  const int tail = HWY_DYNAMIC_DISPATCH(texture_detail::TextureVectors)(u, v, seed, footprint_m,
                                                                          n, out);
  for (int i = tail; i < n; ++i) out[i] = texture_value(u[i], v[i], seed[i], footprint_m[i]);
}

std::string texture_target() {
  return hwy::TargetName(HWY_DYNAMIC_DISPATCH(texture_detail::CurrentTarget)());
}

}  // namespace sg::sim
#endif  // HWY_ONCE
