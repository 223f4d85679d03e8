#include "sg/vision/ego_motion.hpp"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <vector>

#include "sg/core/error.hpp"

namespace sg::vision {
namespace {

/// One sample: its two rows of the linear model and the measured flow.
struct Sample {
  double a[2][6];
  double b[2];
};

}  // namespace

EgoMotion estimate_ego_motion(const cv::Mat& flow, const cv::Mat& disp, const core::Camera& cam,
                              const EgoMotionParams& p) {
  if (flow.type() != CV_32FC2 || disp.type() != CV_32FC1 || flow.size() != disp.size())
    throw core::InputError("ego motion: flow must be CV_32FC2 and disparity CV_32F, same size");
  const double f = cam.focal_px, inv_fb = 1.0 / (cam.focal_px * cam.baseline_m);
  const int step = std::max(1, p.sample_step_px);
  std::vector<Sample> samples;
  for (int v = step / 2; v < disp.rows; v += step) {
    const float* d = disp.ptr<float>(v);
    const cv::Vec2f* fl = flow.ptr<cv::Vec2f>(v);
    for (int u = step / 2; u < disp.cols; u += step) {
      if (!(d[u] >= 0.0f) || !std::isfinite(fl[u][0]) || !std::isfinite(fl[u][1])) continue;
      const double x = u - cam.cx, y = v - cam.cy, rho = d[u] * inv_fb;
      samples.push_back({{{-x * y / f, f + x * x / f, -y, f * rho, 0.0, -x * rho},
                          {-(f + y * y / f), x * y / f, x, 0.0, f * rho, -y * rho}},
                         {fl[u][0], fl[u][1]}});
    }
  }
  EgoMotion m;
  m.samples = static_cast<int>(samples.size());
  if (m.samples < p.min_samples) return m;
  cv::Vec<double, 6> sol = cv::Vec<double, 6>::all(0.0);
  std::vector<double> weight(samples.size(), 1.0);
  for (int it = 0; it < std::max(1, p.iterations); ++it) {
    cv::Matx<double, 6, 6> ata = cv::Matx<double, 6, 6>::zeros();
    cv::Vec<double, 6> atb = cv::Vec<double, 6>::all(0.0);
    for (std::size_t s = 0; s < samples.size(); ++s) {
      const double w = weight[s];
      for (int r = 0; r < 2; ++r) {
        const double* a = samples[s].a[r];
        for (int i = 0; i < 6; ++i) {
          atb[i] += w * a[i] * samples[s].b[r];
          for (int j = 0; j < 6; ++j) ata(i, j) += w * a[i] * a[j];
        }
      }
    }
    if (!cv::solve(ata, atb, sol, cv::DECOMP_CHOLESKY)) return m;
    // Huber weights from the residual of each sample.
    for (std::size_t s = 0; s < samples.size(); ++s) {
      double r2 = 0.0;
      for (int r = 0; r < 2; ++r) {
        double pred = 0.0;
        for (int i = 0; i < 6; ++i) pred += samples[s].a[r][i] * sol[i];
        r2 += (pred - samples[s].b[r]) * (pred - samples[s].b[r]);
      }
      const double res = std::sqrt(r2);
      weight[s] = res <= p.huber_px ? 1.0 : p.huber_px / res;
    }
  }
  m.rotation = {sol[0], sol[1], sol[2]};
  m.translation = {sol[3], sol[4], sol[5]};
  m.valid = true;
  return m;
}

cv::Matx33d derotation(const EgoMotion& m) {
  if (!m.valid) return cv::Matx33d::eye();
  cv::Matx33d r;
  cv::Rodrigues(-m.rotation, r);  // R^T = Rodrigues(-w)
  return r;
}

}  // namespace sg::vision
