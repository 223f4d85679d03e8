#include "sg/vision/segment_motion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "sg/core/error.hpp"
#include "sg/vision/scene_flow.hpp"

namespace sg::vision {
namespace {

bool finite(const cv::Vec3f& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

}  // namespace

float interquartile_mean(std::vector<float>& v) {
  const size_t quarter = v.size() / 4;
  const auto low = v.begin() + static_cast<std::ptrdiff_t>(quarter);
  const auto high = v.end() - static_cast<std::ptrdiff_t>(quarter);
  // Ranks below `quarter` go left of `low`; then, among the rest, ranks from n - quarter go right
  // of `high`: [low, high) holds exactly the middle ranks, in some order.
  std::nth_element(v.begin(), low, v.end());
  if (quarter > 0) std::nth_element(low, high, v.end());
  // In double, so that the order (not the sort's) changes the float result by a rounding at most.
  double sum = 0.0;
  for (auto it = low; it != high; ++it) sum += *it;
  return static_cast<float>(sum / static_cast<double>(high - low));
}

void pool_surface_motion(const cv::Mat& disp, const core::Camera& cam, const core::Envelope& env,
                         const core::SceneFlowParams& p, double span_s, const cv::Mat& edges,
                         cv::Mat& danger, cv::Mat& ttc, cv::Mat& velocity) {
  if (disp.type() != CV_32FC1 || edges.type() != CV_8UC1 || danger.type() != CV_8UC1 ||
      ttc.type() != CV_32FC1 || velocity.type() != CV_32FC3 || edges.size() != disp.size() ||
      danger.size() != disp.size() || ttc.size() != disp.size() || velocity.size() != disp.size())
    throw core::InputError(
        "surface motion: maps must be CV_32F disparity, CV_8U danger, CV_32F TTC and CV_32FC3 "
        "velocity of one size");
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  // The labelling's candidates: valid, near enough, off the depth-edge margin, in the band.
  const float d_min = static_cast<float>(cam.focal_px * cam.baseline_m / p.z_max_m);
  cv::Mat candidate(disp.size(), CV_8UC1);
  for (int y = 0; y < disp.rows; ++y) {
    const float* d = disp.ptr<float>(y);
    const std::uint8_t* e = edges.ptr<std::uint8_t>(y);
    std::uint8_t* c = candidate.ptr<std::uint8_t>(y);
    for (int x = 0; x < disp.cols; ++x) {
      bool ok = d[x] > 0.0f && d[x] >= d_min && e[x] == 0;
      if (ok && p.use_envelope_band) {
        const double Y = (y - cam.cy) * cam.baseline_m / d[x];
        ok = Y >= env.y_top_m && Y <= env.y_bottom_m;
      }
      c[x] = ok ? 255 : 0;
    }
  }
  cv::Mat labels;
  const int count = cv::connectedComponents(candidate, labels, 8, CV_32S);
  // Velocity components per surface, then their interquartile means.
  std::vector<std::vector<float>> vx(static_cast<size_t>(count)), vy(vx.size()), vz(vx.size());
  for (int y = 0; y < disp.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const cv::Vec3f* v = velocity.ptr<cv::Vec3f>(y);
    for (int x = 0; x < disp.cols; ++x) {
      if (l[x] == 0 || !finite(v[x])) continue;
      const auto s = static_cast<size_t>(l[x]);
      vx[s].push_back(v[x][0]);
      vy[s].push_back(v[x][1]);
      vz[s].push_back(v[x][2]);
    }
  }
  std::vector<cv::Vec3f> pooled(static_cast<size_t>(count), cv::Vec3f(kNaN, kNaN, kNaN));
  for (size_t s = 1; s < pooled.size(); ++s)
    if (!vx[s].empty())
      pooled[s] = cv::Vec3f(interquartile_mean(vx[s]), interquartile_mean(vy[s]),
                            interquartile_mean(vz[s]));

  const double max_speed2 = p.max_speed_mps * p.max_speed_mps;
  const double fb = cam.focal_px * cam.baseline_m;
  for (int y = 0; y < disp.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    const float* d = disp.ptr<float>(y);
    std::uint8_t* out = danger.ptr<std::uint8_t>(y);
    float* t = ttc.ptr<float>(y);
    cv::Vec3f* v = velocity.ptr<cv::Vec3f>(y);
    for (int x = 0; x < disp.cols; ++x) {
      out[x] = 0;
      t[x] = kNaN;
      if (l[x] == 0 || !finite(pooled[static_cast<size_t>(l[x])])) {
        v[x] = cv::Vec3f(kNaN, kNaN, kNaN);
        continue;
      }
      const cv::Vec3d V(pooled[static_cast<size_t>(l[x])]);
      v[x] = cv::Vec3f(V);
      const cv::Point3d P = cam.point(x, y, d[x]);
      const double z_before = P.z - V[2] * span_s;
      const bool grew = z_before > 0.0 && d[x] - fb / z_before >= p.min_delta_d_px;
      double t_c = 0.0;
      if (grew && V.dot(V) <= max_speed2 && heads_into_envelope(P, V, env, p.v_min_mps, t_c)) {
        out[x] = 255;
        t[x] = static_cast<float>(t_c);
      }
    }
  }
}

}  // namespace sg::vision
