// The envelope test of pool_surface_motion: a SIMD kernel (Google Highway, compiled once per x86
// target and dispatched at run time) beside its scalar reference. This file is compiled with
// -ffp-contract=off (CMakeLists.txt): a fused multiply-add rounds once where the reference rounds
// twice, and the kernel must equal the reference bit for bit.
#include "sg/vision/surface_test.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "sg/vision/scene_flow.hpp"

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "src/vision/surface_test.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace sg::vision::surface_detail {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

/// Whole vectors of test_surface_run from x0; returns where the scalar tail starts. The
/// operations are those of test_surface_run_reference, lane by lane, in the same order.
int TestRunVectors(const SurfaceTest& k, const cv::Vec3d& V, double keep, int y, int x0, int x1,
                   const float* d, float* ttc) {
  const hn::ScalableTag<double> dd;
  const hn::Rebind<float, decltype(dd)> df;
  const int n = static_cast<int>(hn::Lanes(dd));
  const auto zero = hn::Zero(dd);
  const auto nan = hn::Set(dd, std::numeric_limits<double>::quiet_NaN());
  const auto cx = hn::Set(dd, k.cx);
  const auto focal = hn::Set(dd, k.focal_px);
  const auto fb = hn::Set(dd, k.fb);
  const auto y_off = hn::Set(dd, y - k.cy);
  const auto vz_span = hn::Set(dd, V[2] * k.span_s);
  const auto min_delta = hn::Set(dd, k.min_delta_d_px);
  // V keep, per component as the reference's cv::Vec3d product rounds it.
  const auto keep_v = hn::Set(dd, keep);
  const auto kvx = hn::Set(dd, V[0] * keep), kvy = hn::Set(dd, V[1] * keep);
  const auto kvz = hn::Set(dd, V[2] * keep);
  const auto neg_kvz = hn::Set(dd, -(V[2] * keep));
  const auto neg_v_min = hn::Set(dd, -k.v_min_mps);
  const auto z_contact = hn::Set(dd, k.envelope.z_contact_m);
  const auto horizon = hn::Set(dd, k.envelope.horizon_s);
  const auto half_width = hn::Set(dd, k.envelope.half_width_m);
  const auto y_top = hn::Set(dd, k.envelope.y_top_m);
  const auto y_bottom = hn::Set(dd, k.envelope.y_bottom_m);
  int x = x0;
  for (; x + n <= x1; x += n) {
    const auto disp = hn::PromoteTo(dd, hn::LoadU(df, d + x));
    const auto z = hn::Div(fb, disp);
    const auto px = hn::Div(hn::Mul(hn::Sub(hn::Iota(dd, static_cast<double>(x)), cx), z), focal);
    const auto py = hn::Div(hn::Mul(y_off, z), focal);
    const auto z_before = hn::Sub(z, vz_span);
    const auto t_c = hn::Div(hn::Sub(z, z_contact), neg_kvz);
    const auto ex = hn::Add(px, hn::Mul(kvx, t_c));
    const auto ey = hn::Add(py, hn::Mul(kvy, t_c));
    // Each failed condition turns the lane's TTC into NaN; the negated ones (> instead of <=)
    // fail on NaN as the reference's do.
    auto t = hn::Mul(t_c, keep_v);
    t = hn::IfThenElse(hn::Gt(z_before, zero), t, nan);
    t = hn::IfThenElse(hn::Ge(hn::Sub(disp, hn::Div(fb, z_before)), min_delta), t, nan);
    t = hn::IfThenElse(hn::Le(kvz, neg_v_min), t, nan);
    t = hn::IfThenElse(hn::Gt(t_c, zero), t, nan);
    t = hn::IfThenElse(hn::Gt(t_c, horizon), nan, t);
    t = hn::IfThenElse(hn::Gt(hn::Abs(ex), half_width), nan, t);
    t = hn::IfThenElse(hn::Lt(ey, y_top), nan, t);
    t = hn::IfThenElse(hn::Gt(ey, y_bottom), nan, t);
    hn::StoreU(hn::DemoteTo(df, t), df, ttc + x);
  }
  return x;
}

std::int64_t CurrentTarget() { return HWY_TARGET; }

}  // namespace HWY_NAMESPACE
}  // namespace sg::vision::surface_detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace sg::vision {
namespace surface_detail {
HWY_EXPORT(TestRunVectors);
HWY_EXPORT(CurrentTarget);
}  // namespace surface_detail

namespace {

/// The noise gate at a pixel of disparity disp (depth z = f B / disp): the disparity it had
/// span_s ago at velocity V is at least min_delta_d_px below disp. The one definition both tests
/// use; the SIMD kernel repeats its operations lane by lane.
bool passes_noise_gate(const SurfaceTest& k, const cv::Vec3d& V, double disp, double z) {
  const double z_before = z - V[2] * k.span_s;
  return z_before > 0.0 && disp - k.fb / z_before >= k.min_delta_d_px;
}

}  // namespace

SurfaceTest make_surface_test(const core::Camera& cam, const core::Envelope& env,
                              const core::SceneFlowParams& p, double span_s, double yaw_rate_rps) {
  SurfaceTest k;
  k.cx = cam.cx;
  k.cy = cam.cy;
  k.focal_px = cam.focal_px;
  k.fb = cam.focal_px * cam.baseline_m;
  k.span_s = span_s;
  k.min_delta_d_px = p.min_delta_d_px;
  k.v_min_mps = p.v_min_mps;
  k.yaw_rate_rps = yaw_rate_rps;
  // The fit's slope is the velocity at the middle of its span, in today's orientation: in a turn
  // the platform then headed yaw_rate span / 2 the other way, so the test turns V on by that.
  const double a = -yaw_rate_rps * span_s / 2.0;
  k.turn_cos = std::cos(a);
  k.turn_sin = std::sin(a);
  k.envelope = env;
  return k;
}

void test_surface_run_reference(const SurfaceTest& k, const cv::Vec3d& V, double keep, int y,
                                int x0, int x1, const float* d, float* ttc) {
  const cv::Vec3d kept = V * keep;
  for (int x = x0; x < x1; ++x) {
    ttc[x] = std::numeric_limits<float>::quiet_NaN();
    const double disp = d[x];
    const double z = k.fb / disp;
    if (!passes_noise_gate(k, V, disp, z)) continue;
    const cv::Point3d P((x - k.cx) * z / k.focal_px, (y - k.cy) * z / k.focal_px, z);
    double t_c = 0.0;
    if (heads_into_envelope(P, kept, k.envelope, k.v_min_mps, t_c))
      ttc[x] = static_cast<float>(t_c * keep);  // the TTC of V itself
  }
}

void test_surface_run_turning(const SurfaceTest& k, const cv::Vec3d& V, double keep, int y, int x0,
                              int x1, const float* d, float* ttc) {
  std::fill(ttc + x0, ttc + x1, std::numeric_limits<float>::quiet_NaN());
  cv::Vec3d kept = V * keep;
  kept = {k.turn_cos * kept[0] - k.turn_sin * kept[2], kept[1],
          k.turn_sin * kept[0] + k.turn_cos * kept[2]};
  if (!(kept[2] <= -k.v_min_mps)) return;  // not approaching: no pixel of the run can pass
  for (int x = x0; x < x1; ++x) {
    const double disp = d[x];
    const double z = k.fb / disp;
    if (!passes_noise_gate(k, V, disp, z)) continue;
    const cv::Point3d P((x - k.cx) * z / k.focal_px, (y - k.cy) * z / k.focal_px, z);
    double t_c = 0.0;
    if (heads_into_envelope_turning(P, kept, k.yaw_rate_rps, k.envelope, k.v_min_mps, t_c))
      ttc[x] = static_cast<float>(t_c * keep);  // the TTC of V itself
  }
}

void test_surface_run(const SurfaceTest& k, const cv::Vec3d& V, double keep, int y, int x0, int x1,
                      const float* d, float* ttc) {
  if (k.yaw_rate_rps != 0.0) {
    test_surface_run_turning(k, V, keep, y, x0, x1, d, ttc);
    return;
  }
  const int tail =
      HWY_DYNAMIC_DISPATCH(surface_detail::TestRunVectors)(k, V, keep, y, x0, x1, d, ttc);
  test_surface_run_reference(k, V, keep, y, tail, x1, d, ttc);
}

std::string surface_test_target() {
  return hwy::TargetName(HWY_DYNAMIC_DISPATCH(surface_detail::CurrentTarget)());
}

}  // namespace sg::vision
#endif  // HWY_ONCE
