#include "sg/vision/relative_size.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "sg/core/checker.hpp"
#include "sg/core/error.hpp"
#include "union_find.hpp"

namespace sg::vision {
namespace {

/// The template of side `side` centred at `at`, resampled bilinearly to n x n (CV_32F); false when
/// it leaves the image. Pixel (i, j) of the grid samples at + (side / n) * ((i, j) + 0.5 - n / 2).
bool sample_template(const cv::Mat& image, cv::Point2f at, double side, int n, cv::Mat& out) {
  const double half = side / 2.0;
  if (at.x - half < 0.0 || at.y - half < 0.0 || at.x + half > image.cols - 1 ||
      at.y + half > image.rows - 1)
    return false;
  const double k = side / n;
  const double x0 = at.x + k * (0.5 - n / 2.0), y0 = at.y + k * (0.5 - n / 2.0);
  out.create(n, n, CV_32F);
  for (int j = 0; j < n; ++j) {
    // Inside [0, size - 1] by the check above; the last row and column have weight 0 beyond.
    const double y = y0 + k * j;
    const int iy = std::min(static_cast<int>(y), image.rows - 2);
    const float fy = static_cast<float>(y - iy);
    const std::uint8_t* r0 = image.ptr<std::uint8_t>(iy);
    const std::uint8_t* r1 = image.ptr<std::uint8_t>(iy + 1);
    float* o = out.ptr<float>(j);
    for (int i = 0; i < n; ++i) {
      const double x = x0 + k * i;
      const int ix = std::min(static_cast<int>(x), image.cols - 2);
      const float fx = static_cast<float>(x - ix);
      const float top = r0[ix] + fx * (r0[ix + 1] - r0[ix]);
      const float bottom = r1[ix] + fx * (r1[ix + 1] - r1[ix]);
      o[i] = top + fy * (bottom - top);
    }
  }
  return true;
}

/// patch_scale over the logarithmic grid of scales exp(i log(1 + scale_step)), i in
/// [i_min, i_max], the images and parameters already checked. With `stride` > 1 the grid is
/// searched at every stride-th index first, then at every index within a stride of the best one
/// (coarse to fine: the template error is smooth in the scale, its minimum a few steps wide).
double search_scale(const cv::Mat& prev, const cv::Mat& cur, cv::Point2f at_prev,
                    cv::Point2f at_cur, double side_px, const RelativeSizeParams& p, int i_min,
                    int i_max, double* error, int stride = 1) {
  cv::Mat reference, candidate;
  if (!sample_template(prev, at_prev, side_px, p.template_px, reference)) return 0.0;
  const double log_step = std::log1p(p.scale_step);
  // The error at grid index i; infinity where the template leaves the image.
  auto error_at = [&](int i) {
    if (!sample_template(cur, at_cur, side_px * std::exp(i * log_step), p.template_px, candidate))
      return std::numeric_limits<double>::infinity();
    return cv::norm(reference, candidate, cv::NORM_L1) / static_cast<double>(reference.total());
  };
  int lo = i_min, hi = i_max;
  if (stride > 1) {
    int coarse = i_min;
    double coarse_error = std::numeric_limits<double>::infinity();
    for (int i = i_min; i <= i_max; i += stride) {
      const double e = error_at(i);
      if (e < coarse_error) coarse_error = e, coarse = i;
    }
    if (!std::isfinite(coarse_error)) return 0.0;
    lo = std::max(i_min, coarse - stride);
    hi = std::min(i_max, coarse + stride);
  }
  std::vector<double> errors;
  std::vector<int> index;
  for (int i = lo; i <= hi; ++i) {
    const double e = error_at(i);
    if (!std::isfinite(e)) continue;
    index.push_back(i);
    errors.push_back(e);
  }
  if (errors.empty()) return 0.0;
  const size_t best = static_cast<size_t>(std::min_element(errors.begin(), errors.end()) -
                                          errors.begin());
  double log_s = index[best] * log_step;
  // A parabola through the least error and its neighbours (on the log grid) refines it.
  if (best > 0 && best + 1 < errors.size() && index[best - 1] + 1 == index[best] &&
      index[best + 1] - 1 == index[best]) {
    const double a = errors[best - 1], b = errors[best], c = errors[best + 1];
    const double denominator = a - 2.0 * b + c;
    if (denominator > 0.0) log_s += 0.5 * (a - c) / denominator * log_step;
  }
  if (error) *error = errors[best];
  return std::exp(log_s);
}

/// expanding_features searches every kCoarseStride-th scale first (4 % apart), then every one
/// near the best: 17 templates a feature instead of 44 (test
/// RelativeSize.CoarseToFineFindsTheScaleOfTheFullSearch).
constexpr int kCoarseStride = 4;

/// The grid's largest index: exp(i log(1 + scale_step)) reaches scale_max.
int scale_steps(const RelativeSizeParams& p) {
  return static_cast<int>(std::ceil(std::log(p.scale_max) / std::log1p(p.scale_step)));
}

void check_images(const cv::Mat& prev, const cv::Mat& cur) {
  if (prev.type() != CV_8UC1 || cur.type() != CV_8UC1 || prev.size() != cur.size() ||
      prev.empty())
    throw core::InputError("relative size: two non-empty 8-bit grey images of one size");
}

}  // namespace

double patch_scale(const cv::Mat& prev, const cv::Mat& cur, cv::Point2f at_prev,
                   cv::Point2f at_cur, double side_px, const RelativeSizeParams& p,
                   double* error, int coarse_stride) {
  check_images(prev, cur);
  core::throw_if_invalid(validate(p), "invalid parameters");
  const int steps = scale_steps(p);
  return search_scale(prev, cur, at_prev, at_cur, side_px, p, -steps, steps, error,
                      std::max(1, coarse_stride));
}

std::vector<ExpandingFeature> expanding_features(const cv::Mat& prev, const cv::Mat& cur,
                                                 const RelativeSizeParams& p) {
  check_images(prev, cur);
  core::throw_if_invalid(validate(p), "invalid parameters");
  cv::Ptr<cv::ORB> orb = cv::ORB::create(p.max_features);
  std::vector<cv::KeyPoint> k0, k1;
  cv::Mat d0, d1;
  orb->detectAndCompute(prev, cv::noArray(), k0, d0);
  orb->detectAndCompute(cur, cv::noArray(), k1, d1);
  std::vector<ExpandingFeature> out;
  if (k0.empty() || k1.size() < 2) return out;
  cv::BFMatcher matcher(cv::NORM_HAMMING);
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(d0, d1, knn, 2);
  for (const std::vector<cv::DMatch>& m : knn) {
    if (m.size() < 2 || m[0].distance > p.ratio_test * m[1].distance) continue;
    const cv::KeyPoint& a = k0[static_cast<size_t>(m[0].queryIdx)];
    const cv::KeyPoint& b = k1[static_cast<size_t>(m[0].trainIdx)];
    // Only features whose detected size did not shrink can be expanding (the thesis keeps those
    // of bigger scale; ORB's pyramid levels are coarse, so equal sizes are kept too).
    if (b.size < a.size) continue;
    // Growing scales only (from two steps below 1, so that a least error at 1 still has its
    // parabola): a shrinking feature is not expanding whatever its exact scale.
    double error = 0.0;
    const double s = search_scale(prev, cur, a.pt, b.pt, a.size * p.patch_factor, p, -2,
                                  scale_steps(p), &error, kCoarseStride);
    if (s < p.s_min || error > p.max_error) continue;
    out.push_back({b.pt, s, -1});
  }
  // Single-linkage clusters.
  std::vector<int> parent(out.size());
  for (size_t i = 0; i < out.size(); ++i) parent[i] = static_cast<int>(i);
  const double r2 = p.cluster_radius_px * p.cluster_radius_px;
  for (size_t i = 0; i < out.size(); ++i)
    for (size_t j = i + 1; j < out.size(); ++j) {
      const cv::Point2f d = out[i].at - out[j].at;
      if (d.dot(d) <= r2) detail::unite_roots(parent, static_cast<int>(i), static_cast<int>(j));
    }
  std::vector<int> size(out.size(), 0), id(out.size(), -1);
  for (size_t i = 0; i < out.size(); ++i)
    ++size[static_cast<size_t>(detail::find_root(parent, static_cast<int>(i)))];
  int clusters = 0;
  for (size_t i = 0; i < out.size(); ++i) {
    const auto root = static_cast<size_t>(detail::find_root(parent, static_cast<int>(i)));
    if (size[root] < p.cluster_min) continue;
    if (id[root] < 0) id[root] = clusters++;
    out[i].cluster = id[root];
  }
  return out;
}

}  // namespace sg::vision
