#include "sg/vision/surveyed.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "sg/core/error.hpp"
#include "sg/vision/elevation_map.hpp"
#include "sg/vision/relative_size.hpp"
#include "sg/vision/scene_flow.hpp"
#include "sg/vision/sceneflow_seg.hpp"

namespace sg::vision {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

void allocate(cv::Size size, cv::Mat& danger, cv::Mat& ttc) {
  danger.create(size, CV_8U);
  danger.setTo(0);
  ttc.create(size, CV_32F);
  ttc.setTo(kNaN);
}

/// `blob` (CV_8U, 0/255) with the holes it encloses filled: what no 4-connected path of zeros
/// joins to the border.
cv::Mat filled(const cv::Mat& blob) {
  cv::Mat padded = cv::Mat::zeros(blob.rows + 2, blob.cols + 2, CV_8U);
  blob.copyTo(padded(cv::Rect(1, 1, blob.cols, blob.rows)));
  cv::floodFill(padded, cv::Point(0, 0), 128, nullptr, 0, 0, 4);
  return padded(cv::Rect(1, 1, blob.cols, blob.rows)) != 128;
}

/// The median of `v` (reordered); v must not be empty.
double median_of(std::vector<double>& v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

double expansion_rate(const cv::Mat& forward_flow, const cv::Mat& mask) {
  double n = 0, sx = 0, sy = 0, su = 0, sv = 0, sxu = 0, syv = 0, sxx = 0, syy = 0;
  for (int y = 0; y < mask.rows; ++y) {
    const uchar* m = mask.ptr<uchar>(y);
    const cv::Vec2f* f = forward_flow.ptr<cv::Vec2f>(y);
    for (int x = 0; x < mask.cols; ++x) {
      if (!m[x] || !std::isfinite(f[x][0]) || !std::isfinite(f[x][1])) continue;
      n += 1;
      sx += x;
      sy += y;
      su += f[x][0];
      sv += f[x][1];
      sxu += x * static_cast<double>(f[x][0]);
      syv += y * static_cast<double>(f[x][1]);
      sxx += static_cast<double>(x) * x;
      syy += static_cast<double>(y) * y;
    }
  }
  if (n < 2) return 0.0;
  const double cov = (sxu - sx * su / n) + (syv - sy * sv / n);
  const double var = (sxx - sx * sx / n) + (syy - sy * sy / n);
  return var > 0 ? cov / var : 0.0;
}

void label_motion_parallax(const cv::Mat& backward_flow, double dt_s,
                           const core::MotionParallaxParams& p, int min_area_px, double horizon_s,
                           cv::Mat& danger, cv::Mat& ttc) {
  if (backward_flow.empty() || backward_flow.type() != CV_32FC2)
    throw core::InputError("motion parallax: the flow must be a non-empty CV_32FC2 map");
  if (!(dt_s > 0)) throw core::InputError("motion parallax: the frames must be apart in time");
  allocate(backward_flow.size(), danger, ttc);
  cv::Mat forward = -backward_flow;
  cv::patchNaNs(forward, 0.0);
  cv::Mat smooth;  // not a share of `forward`: the blur would write into it
  if (p.smooth_px > 1)
    cv::blur(forward, smooth, cv::Size(p.smooth_px, p.smooth_px));
  else
    smooth = forward;
  // Moving: by the smoothed flow (the blobs), and by the flow itself (the fit: the smoothing
  // spreads a blob's flow over its still surroundings, which would bias its rate low).
  const double min_px = p.flow_min_px_s * dt_s;
  cv::Mat moving(forward.size(), CV_8U), moving_raw(forward.size(), CV_8U);
  for (int y = 0; y < forward.rows; ++y) {
    const cv::Vec2f* f = forward.ptr<cv::Vec2f>(y);
    const cv::Vec2f* s = smooth.ptr<cv::Vec2f>(y);
    uchar* m = moving.ptr<uchar>(y);
    uchar* r = moving_raw.ptr<uchar>(y);
    for (int x = 0; x < forward.cols; ++x) {
      m[x] = std::hypot(s[x][0], s[x][1]) >= min_px ? 255 : 0;
      r[x] = std::hypot(f[x][0], f[x][1]) >= min_px ? 255 : 0;
    }
  }
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(moving, labels, stats, centroids, 8, CV_32S);
  for (int l = 1; l < count; ++l) {
    if (stats.at<int>(l, cv::CC_STAT_AREA) < min_area_px) continue;
    const cv::Rect box(stats.at<int>(l, cv::CC_STAT_LEFT), stats.at<int>(l, cv::CC_STAT_TOP),
                       stats.at<int>(l, cv::CC_STAT_WIDTH), stats.at<int>(l, cv::CC_STAT_HEIGHT));
    // An approaching object's flow vanishes at its focus of expansion: its blob is what the
    // moving pixels enclose.
    const cv::Mat blob = labels(box) == l;
    const cv::Mat fit = filled(blob & moving_raw(box));
    // The rate is measured in the box's coordinates: a translation of the origin leaves k alone.
    const double k = expansion_rate(forward(box), fit);
    if (k <= 0) continue;
    const double tau = dt_s / k;
    if (tau > horizon_s) continue;
    const cv::Mat marked = filled(blob);
    danger(box).setTo(255, marked);
    ttc(box).setTo(static_cast<float>(tau), marked);
  }
}

void label_relative_size(const cv::Mat& earlier, const cv::Mat& current, double span_s,
                         const core::RelativeSizeParams& p, double horizon_s, cv::Mat& danger,
                         cv::Mat& ttc) {
  if (!(span_s > 0)) throw core::InputError("relative size: the frames must be apart in time");
  const std::vector<ExpandingFeature> features = expanding_features(earlier, current, p);
  allocate(current.size(), danger, ttc);
  std::map<int, std::vector<const ExpandingFeature*>> clusters;
  for (const ExpandingFeature& f : features)
    if (f.cluster >= 0) clusters[f.cluster].push_back(&f);
  const int radius = std::max(1, p.template_px / 2);
  for (const auto& [id, members] : clusters) {
    std::vector<double> scales;
    std::vector<cv::Point> points;
    for (const ExpandingFeature* f : members) {
      scales.push_back(f->scale);
      points.emplace_back(cvRound(f->at.x), cvRound(f->at.y));
    }
    const double s = median_of(scales);
    if (s <= 1.0) continue;
    const double tau = span_s / (s - 1.0);
    if (tau > horizon_s) continue;
    cv::Mat blob = cv::Mat::zeros(current.size(), CV_8U);
    std::vector<cv::Point> hull;
    cv::convexHull(points, hull);
    cv::fillConvexPoly(blob, hull, 255);
    for (const cv::Point& q : points) cv::circle(blob, q, radius, 255, cv::FILLED);
    danger.setTo(255, blob);
    ttc.setTo(static_cast<float>(tau), blob);
  }
}

void label_proximity(const cv::Mat& disp, const cv::Mat& allowed, const core::Camera& cam,
                     const core::Envelope& envelope, const core::ProximityParams& p,
                     cv::Mat& danger, cv::Mat& ttc) {
  if (disp.empty() || disp.type() != CV_32F)
    throw core::InputError("proximity: the disparity must be a non-empty CV_32F map");
  if (!allowed.empty() && (allowed.type() != CV_8U || allowed.size() != disp.size()))
    throw core::InputError("proximity: the mask must be CV_8U of the disparity's size");
  allocate(disp.size(), danger, ttc);
  const double d_min = cam.disparity(p.alarm_distance_m);
  for (int y = 0; y < disp.rows; ++y) {
    const float* d = disp.ptr<float>(y);
    const uchar* a = allowed.empty() ? nullptr : allowed.ptr<uchar>(y);
    uchar* out = danger.ptr<uchar>(y);
    for (int x = 0; x < disp.cols; ++x) {
      if (!(d[x] > 0) || d[x] < d_min || (a && !a[x])) continue;
      const cv::Point3d P = cam.point(x, y, d[x]);
      if (std::abs(P.x) <= envelope.half_width_m && P.y >= envelope.y_top_m &&
          P.y <= envelope.y_bottom_m)
        out[x] = 255;
    }
  }
}

void label_elevation_map(const cv::Mat& disp, const core::Camera& cam,
                         const core::Envelope& envelope, const core::ElevationParams& p,
                         const core::ProximityParams& proximity, cv::Mat& danger, cv::Mat& ttc) {
  const RoadModel road = fit_road(disp, cam, p);
  if (!road.found) {
    allocate(disp.size(), danger, ttc);
    return;
  }
  const ElevationMap map = build_elevation_map(disp, cam, road, p);
  cv::Mat obstacles;
  mark_elevation_obstacles(disp, cam, road, map, p, obstacles);
  label_proximity(disp, obstacles, cam, envelope, proximity, danger, ttc);
}

void label_sceneflow_seg(const cv::Mat& left, const cv::Mat& disp, const cv::Mat& disp_prev,
                         const cv::Mat& backward_flow, double dt_s, const core::Camera& cam,
                         const core::Envelope& envelope, const core::SceneFlowSegParams& p,
                         int min_area_px, cv::Mat& danger, cv::Mat& ttc, cv::Mat& velocity) {
  if (!(dt_s > 0)) throw core::InputError("scene-flow segmentation: frames must be apart in time");
  if (left.type() != CV_8UC1 || left.size() != disp.size())
    throw core::InputError("scene-flow segmentation: an 8-bit left image of the disparity's size");
  cv::Mat xi;
  motion_likelihood(disp, disp_prev, backward_flow, cam, p, xi);
  allocate(disp.size(), danger, ttc);
  velocity.create(disp.size(), CV_32FC3);
  velocity.setTo(cv::Scalar::all(kNaN));

  // The cut on a coarser grid: cell averages of the likelihood (no evidence = xi_static).
  cv::Mat xi_known = xi.clone();
  cv::patchNaNs(xi_known, p.xi_static);
  cv::Mat moving;
  if (p.grid_step_px > 1) {
    const cv::Size grid((disp.cols + p.grid_step_px - 1) / p.grid_step_px,
                        (disp.rows + p.grid_step_px - 1) / p.grid_step_px);
    cv::Mat small_image, small_xi, small_moving;
    cv::resize(left, small_image, grid, 0, 0, cv::INTER_AREA);
    cv::resize(xi_known, small_xi, grid, 0, 0, cv::INTER_AREA);
    segment_moving(small_image, small_xi, p, small_moving);
    cv::resize(small_moving, moving, disp.size(), 0, 0, cv::INTER_NEAREST);
  } else {
    segment_moving(left, xi_known, p, moving);
  }

  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(moving, labels, stats, centroids, 8, CV_32S);
  struct Samples {
    std::vector<double> px, py, pz, vx, vy, vz;
  };
  std::vector<Samples> blobs(static_cast<size_t>(count));
  for (int y = 0; y < disp.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const float* d = disp.ptr<float>(y);
    const cv::Vec2f* b = backward_flow.ptr<cv::Vec2f>(y);
    for (int x = 0; x < disp.cols; ++x) {
      if (l[x] == 0 || stats.at<int>(l[x], cv::CC_STAT_AREA) < min_area_px || !(d[x] > 0))
        continue;
      const cv::Point2f q(x + b[x][0], y + b[x][1]);
      float d_prev = 0;
      if (!sample_disparity_bilinear(disp_prev, q.x, q.y, d_prev)) continue;
      cv::Vec3d V;
      cv::Point3d P;
      if (!point_velocity(cv::Point2f(static_cast<float>(x), static_cast<float>(y)), d[x], q,
                          d_prev, cam, dt_s, V, P))
        continue;
      Samples& s = blobs[static_cast<size_t>(l[x])];
      s.px.push_back(P.x);
      s.py.push_back(P.y);
      s.pz.push_back(P.z);
      s.vx.push_back(V[0]);
      s.vy.push_back(V[1]);
      s.vz.push_back(V[2]);
    }
  }
  for (int l = 1; l < count; ++l) {
    Samples& s = blobs[static_cast<size_t>(l)];
    if (s.px.empty()) continue;
    const cv::Point3d P(median_of(s.px), median_of(s.py), median_of(s.pz));
    const cv::Vec3d V(median_of(s.vx), median_of(s.vy), median_of(s.vz));
    const cv::Rect box(stats.at<int>(l, cv::CC_STAT_LEFT), stats.at<int>(l, cv::CC_STAT_TOP),
                       stats.at<int>(l, cv::CC_STAT_WIDTH), stats.at<int>(l, cv::CC_STAT_HEIGHT));
    const cv::Mat blob = labels(box) == l;
    velocity(box).setTo(cv::Scalar(V[0], V[1], V[2]), blob);
    double t_contact = 0;
    if (!heads_into_envelope(P, V, envelope, p.v_min_mps, t_contact)) continue;
    danger(box).setTo(255, blob);
    ttc(box).setTo(static_cast<float>(t_contact), blob);
  }
}

}  // namespace sg::vision
