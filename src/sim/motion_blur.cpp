// motion_blur: the samples of the exposure's blur taken as cv::remap takes them (INTER_LINEAR,
// BORDER_REPLICATE, from a float map), a SIMD kernel (Google Highway, compiled once per x86 target
// and dispatched at run time) with a scalar pixel for tails and far-off positions, beside the
// reference that calls cv::remap. This file is compiled with -ffp-contract=off (CMakeLists.txt):
// the weighted sum must round as cv::remap's does, with no fused multiply-adds.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>

#ifndef SG_SIM_MOTION_BLUR_SHARED
#define SG_SIM_MOTION_BLUR_SHARED
namespace sg::sim::blur_detail {

constexpr int kTabBits = 5;  // cv::remap rounds positions to 1/32 px (INTER_BITS)
constexpr int kTabSize = 1 << kTabBits;
/// Beyond this |coordinate| (px) the position times 32 may leave the int range, where cv::remap's
/// rounding wraps; such pixels take the scalar path, which rounds as it does.
constexpr float kSafeCoordinate = 6.0e7f;

/// One row of the image to sample, and where the samples go.
struct BlurRow {
  const float* source = nullptr;  // CV_32FC1 image, row 0
  std::size_t stride = 0;         // floats between its rows
  int width = 0, height = 0;
  int y = 0;
  const float* flow = nullptr;  // row y of the CV_32FC2 flow, interleaved
  double offset = 0.0;          // the sample's position along the flow, in units of it
  float* sum = nullptr;         // row y of the samples' running sum
};

/// Adds the sample at pixel x of the row to its sum, as cv::remap computes it: the position
/// (x + offset * flow) in double, then float, rounded to 1/32 px (cvRound), its whole part by an
/// arithmetic shift, the four neighbours clamped to the image, and their weights products of
/// multiples of 1/32 (exact in float), summed left to right.
inline void sample_pixel(const BlurRow& r, int x) {
  const float sx = static_cast<float>(x + r.offset * r.flow[2 * x]);
  const float sy = static_cast<float>(r.y + r.offset * r.flow[2 * x + 1]);
  const int fx = cvRound(sx * static_cast<float>(kTabSize));
  const int fy = cvRound(sy * static_cast<float>(kTabSize));
  const int x0 = fx >> kTabBits, y0 = fy >> kTabBits;
  const float ax = static_cast<float>(fx & (kTabSize - 1)) * (1.0f / kTabSize);
  const float ay = static_cast<float>(fy & (kTabSize - 1)) * (1.0f / kTabSize);
  const int xa = std::clamp(x0, 0, r.width - 1), xb = std::clamp(x0 + 1, 0, r.width - 1);
  const float* top =
      r.source + static_cast<std::size_t>(std::clamp(y0, 0, r.height - 1)) * r.stride;
  const float* bottom =
      r.source + static_cast<std::size_t>(std::clamp(y0 + 1, 0, r.height - 1)) * r.stride;
  r.sum[x] += top[xa] * ((1.0f - ay) * (1.0f - ax)) + top[xb] * ((1.0f - ay) * ax) +
              bottom[xa] * (ay * (1.0f - ax)) + bottom[xb] * (ay * ax);
}

}  // namespace sg::sim::blur_detail
#endif  // SG_SIM_MOTION_BLUR_SHARED

#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "src/sim/motion_blur.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace sg::sim::blur_detail {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

/// sample_pixel for whole vectors of pixels from x, lane by lane in the same operations; stops
/// at the first vector that would pass the row's end or holds a position beyond kSafeCoordinate,
/// and returns its x (the caller samples that pixel and calls again).
int SampleVectors(const BlurRow& r, int x) {
  const hn::ScalableTag<double> dd;
  const hn::Rebind<float, decltype(dd)> df;
  const hn::Rebind<std::int32_t, decltype(dd)> di;
  const int lanes = static_cast<int>(hn::Lanes(dd));
  const auto offset = hn::Set(dd, r.offset), row = hn::Set(dd, static_cast<double>(r.y));
  const auto scale = hn::Set(df, static_cast<float>(kTabSize));
  const auto safe = hn::Set(df, kSafeCoordinate);
  const auto frac = hn::Set(di, kTabSize - 1), zero = hn::Zero(di), one_i = hn::Set(di, 1);
  const auto minus_one = hn::Set(di, -1), lane = hn::Iota(di, 0);
  const auto last_x = hn::Set(di, r.width - 1), last_y = hn::Set(di, r.height - 1);
  const auto stride = hn::Set(di, static_cast<std::int32_t>(r.stride));
  const auto step = hn::Set(df, 1.0f / kTabSize), one = hn::Set(df, 1.0f);
  for (; x + lanes <= r.width; x += lanes) {
    hn::Vec<decltype(df)> qx, qy;
    hn::LoadInterleaved2(df, r.flow + 2 * x, qx, qy);
    const auto xs = hn::Iota(dd, static_cast<double>(x));
    const auto sx = hn::DemoteTo(df, hn::Add(xs, hn::Mul(offset, hn::PromoteTo(dd, qx))));
    const auto sy = hn::DemoteTo(df, hn::Add(row, hn::Mul(offset, hn::PromoteTo(dd, qy))));
    if (!hn::AllTrue(df, hn::And(hn::Lt(hn::Abs(sx), safe), hn::Lt(hn::Abs(sy), safe)))) break;
    const auto fx = hn::NearestInt(hn::Mul(sx, scale));
    const auto fy = hn::NearestInt(hn::Mul(sy, scale));
    const auto x0 = hn::ShiftRight<kTabBits>(fx), y0 = hn::ShiftRight<kTabBits>(fy);
    const auto ax = hn::Mul(hn::ConvertTo(df, hn::And(fx, frac)), step);
    const auto ay = hn::Mul(hn::ConvertTo(df, hn::And(fy, frac)), step);
    hn::Vec<decltype(df)> t0, t1, b0, b1;
    const auto inside = hn::And(hn::And(hn::Gt(x0, minus_one), hn::Lt(x0, last_x)),
                                hn::And(hn::Gt(y0, minus_one), hn::Lt(y0, last_y)));
    const auto first = hn::Sub(x0, lane);  // x0 - lane index: one value where x0 runs on by 1
    const std::int32_t x_first = hn::GetLane(first), y_first = hn::GetLane(y0);
    if (hn::AllTrue(di, inside) && hn::AllTrue(di, hn::Eq(first, hn::Set(di, x_first))) &&
        hn::AllTrue(di, hn::Eq(y0, hn::Set(di, y_first)))) {
      // The lanes' neighbours are consecutive pixels of two rows (a flow that varies by less
      // than a pixel along the vector): plain loads.
      const float* top = r.source + static_cast<std::size_t>(y_first) * r.stride + x_first;
      t0 = hn::LoadU(df, top);
      t1 = hn::LoadU(df, top + 1);
      b0 = hn::LoadU(df, top + r.stride);
      b1 = hn::LoadU(df, top + r.stride + 1);
    } else {
      const auto xa = hn::Min(hn::Max(x0, zero), last_x);
      const auto xb = hn::Min(hn::Max(hn::Add(x0, one_i), zero), last_x);
      const auto top = hn::Mul(hn::Min(hn::Max(y0, zero), last_y), stride);
      const auto bottom = hn::Mul(hn::Min(hn::Max(hn::Add(y0, one_i), zero), last_y), stride);
      t0 = hn::GatherIndex(df, r.source, hn::Add(top, xa));
      t1 = hn::GatherIndex(df, r.source, hn::Add(top, xb));
      b0 = hn::GatherIndex(df, r.source, hn::Add(bottom, xa));
      b1 = hn::GatherIndex(df, r.source, hn::Add(bottom, xb));
    }
    const auto ry = hn::Sub(one, ay), rx = hn::Sub(one, ax);
    auto value = hn::Add(hn::Mul(t0, hn::Mul(ry, rx)), hn::Mul(t1, hn::Mul(ry, ax)));
    value = hn::Add(value, hn::Mul(b0, hn::Mul(ay, rx)));
    value = hn::Add(value, hn::Mul(b1, hn::Mul(ay, ax)));
    hn::StoreU(hn::Add(hn::LoadU(df, r.sum + x), value), df, r.sum + x);
  }
  return x;
}

}  // namespace HWY_NAMESPACE
}  // namespace sg::sim::blur_detail
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include <opencv2/imgproc.hpp>

#include "sg/sim/motion_blur.hpp"

namespace sg::sim {
namespace blur_detail {
HWY_EXPORT(SampleVectors);
}  // namespace blur_detail
namespace {

/// Samples of the blur: one per pixel of the longest displacement during the exposure, 2..12.
int sample_count(const cv::Mat& flow, double share) {
  double longest2 = 0.0;
  for (int y = 0; y < flow.rows; ++y) {
    const auto* q = flow.ptr<cv::Vec2f>(y);
    for (int x = 0; x < flow.cols; ++x)
      longest2 = std::max(longest2, static_cast<double>(q[x][0] * q[x][0] + q[x][1] * q[x][1]));
  }
  return std::clamp(static_cast<int>(std::ceil(std::sqrt(longest2) * share)) + 1, 2, 12);
}

/// Position of sample k of n along the flow, in units of the flow.
double sample_offset(double share, int k, int n) {
  return share * (0.5 - static_cast<double>(k) / (n - 1));
}

/// The mean of the samples and the noise, from their sum, as the reference finishes it.
void finish(cv::Mat& sum, int n, const cv::Mat& noise, cv::Mat& gray) {
  sum *= 1.0 / n;
  if (!noise.empty()) sum += noise;
  sum.convertTo(gray, CV_8UC1);  // rounds and saturates
}

}  // namespace

void motion_blur(cv::Mat& gray, const cv::Mat& flow, double share, const cv::Mat& noise) {
  const int n = sample_count(flow, share);
  cv::Mat source, sum(gray.size(), CV_32FC1);
  gray.convertTo(source, CV_32FC1);
  blur_detail::BlurRow base;
  base.source = source.ptr<float>(0);
  base.stride = source.step1();
  base.width = gray.cols;
  base.height = gray.rows;
  cv::parallel_for_(cv::Range(0, gray.rows), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      blur_detail::BlurRow r = base;
      r.y = y;
      r.flow = flow.ptr<float>(y);
      r.sum = sum.ptr<float>(y);
      std::fill(r.sum, r.sum + r.width, 0.0f);
      for (int k = 0; k < n; ++k) {
        r.offset = sample_offset(share, k, n);
        for (int x = 0; x < r.width; ++x) {
          x = HWY_DYNAMIC_DISPATCH(blur_detail::SampleVectors)(r, x);
          if (x < r.width) blur_detail::sample_pixel(r, x);
        }
      }
    }
  });
  finish(sum, n, noise, gray);
}

void motion_blur_reference(cv::Mat& gray, const cv::Mat& flow, double share, const cv::Mat& noise) {
  const int n = sample_count(flow, share);
  cv::Mat source, sum = cv::Mat::zeros(gray.size(), CV_32FC1), sample;
  gray.convertTo(source, CV_32FC1);
  cv::Mat map(gray.size(), CV_32FC2);
  for (int k = 0; k < n; ++k) {
    const double c = sample_offset(share, k, n);
    for (int y = 0; y < map.rows; ++y) {
      const auto* q = flow.ptr<cv::Vec2f>(y);
      auto* m = map.ptr<cv::Vec2f>(y);
      for (int x = 0; x < map.cols; ++x)
        m[x] = cv::Vec2f(static_cast<float>(x + c * q[x][0]), static_cast<float>(y + c * q[x][1]));
    }
    cv::remap(source, sample, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    sum += sample;
  }
  finish(sum, n, noise, gray);
}

}  // namespace sg::sim
#endif  // HWY_ONCE
