#include "sg/vision/relative_size.hpp"

#include <cmath>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "sg/core/checker.hpp"
#include "sg/core/error.hpp"
#include "union_find.hpp"

namespace sg::vision {
namespace {

/// The template of side `side` centred at `at`, resampled bilinearly to n x n (CV_32F); false when
/// it leaves the image.
bool sample_template(const cv::Mat& image, cv::Point2f at, double side, int n, cv::Mat& out) {
  const double half = side / 2.0;
  if (at.x - half < 0.0 || at.y - half < 0.0 || at.x + half > image.cols - 1 ||
      at.y + half > image.rows - 1)
    return false;
  // Pixel (i, j) of the grid samples at + (side / n) * ((i, j) + 0.5 - n / 2).
  const double k = side / n;
  const cv::Matx23d affine(k, 0.0, at.x + k * (0.5 - n / 2.0),  //
                           0.0, k, at.y + k * (0.5 - n / 2.0));
  cv::warpAffine(image, out, affine, cv::Size(n, n), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                 cv::BORDER_REPLICATE);
  out.convertTo(out, CV_32F);
  return true;
}

void check_images(const cv::Mat& prev, const cv::Mat& cur) {
  if (prev.type() != CV_8UC1 || cur.type() != CV_8UC1 || prev.size() != cur.size() ||
      prev.empty())
    throw core::InputError("relative size: two non-empty 8-bit grey images of one size");
}

}  // namespace

std::vector<std::string> validate(const RelativeSizeParams& p) {
  std::vector<std::string> out;
  core::Checker c(out, "relative_size");
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  c.require(p.max_features >= 10 && p.max_features <= 100000, "max_features", p.max_features,
            "must be in 10..100000");
  c.require(positive(p.ratio_test) && p.ratio_test <= 1.0, "ratio_test", p.ratio_test,
            "must be in (0, 1]");
  c.require(p.template_px >= 4 && p.template_px <= 128, "template_px", p.template_px,
            "must be in 4..128 (px)");
  c.require(positive(p.patch_factor), "patch_factor", p.patch_factor, "must be > 0");
  c.require(std::isfinite(p.scale_max) && p.scale_max > 1.0 && p.scale_max <= 4.0, "scale_max",
            p.scale_max, "must be in (1, 4]");
  c.require(positive(p.scale_step) && p.scale_step <= 0.1, "scale_step", p.scale_step,
            "must be in (0, 0.1]");
  c.require(std::isfinite(p.s_min) && p.s_min > 1.0, "s_min", p.s_min, "must be > 1");
  c.require(positive(p.max_error), "max_error", p.max_error, "must be > 0 (grey levels)");
  c.require(positive(p.cluster_radius_px), "cluster_radius_px", p.cluster_radius_px,
            "must be > 0 (px)");
  c.require(p.cluster_min >= 1, "cluster_min", p.cluster_min, "must be >= 1");
  return out;
}

double patch_scale(const cv::Mat& prev, const cv::Mat& cur, cv::Point2f at_prev,
                   cv::Point2f at_cur, double side_px, const RelativeSizeParams& p,
                   double* error) {
  check_images(prev, cur);
  core::throw_if_invalid(validate(p), "invalid parameters");
  cv::Mat reference, candidate;
  if (!sample_template(prev, at_prev, side_px, p.template_px, reference)) return 0.0;
  // Scales on a logarithmic grid, so that growing and shrinking are searched alike.
  const double log_max = std::log(p.scale_max), log_step = std::log1p(p.scale_step);
  const int steps = static_cast<int>(std::ceil(log_max / log_step));
  std::vector<double> errors;
  std::vector<double> scales;
  for (int i = -steps; i <= steps; ++i) {
    const double s = std::exp(i * log_step);
    if (!sample_template(cur, at_cur, side_px * s, p.template_px, candidate)) continue;
    scales.push_back(s);
    errors.push_back(cv::norm(reference, candidate, cv::NORM_L1) / reference.total());
  }
  if (errors.empty()) return 0.0;
  const size_t best = static_cast<size_t>(std::min_element(errors.begin(), errors.end()) -
                                          errors.begin());
  double log_s = std::log(scales[best]);
  // A parabola through the least error and its neighbours (on the log grid) refines it.
  if (best > 0 && best + 1 < errors.size()) {
    const double a = errors[best - 1], b = errors[best], c = errors[best + 1];
    const double denominator = a - 2.0 * b + c;
    if (denominator > 0.0) log_s += 0.5 * (a - c) / denominator * log_step;
  }
  if (error) *error = errors[best];
  return std::exp(log_s);
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
    double error = 0.0;
    const double s = patch_scale(prev, cur, a.pt, b.pt, a.size * p.patch_factor, p, &error);
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
