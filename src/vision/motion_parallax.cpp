#include "sg/vision/motion_parallax.hpp"

#include <cmath>

#include "sg/core/error.hpp"

namespace sg::vision {

ParallaxScore motion_parallax(const cv::Mat& backward_flow, double dt_s) {
  if (backward_flow.type() != CV_32FC2 || backward_flow.empty())
    throw core::InputError("motion parallax: the flow must be a non-empty CV_32FC2 map");
  if (!(dt_s > 0.0) || !std::isfinite(dt_s))
    throw core::InputError("motion parallax: the time between frames must be > 0 s");
  const int half = backward_flow.cols / 2;
  double sum[2] = {0.0, 0.0};
  int count[2] = {0, 0};
  for (int y = 0; y < backward_flow.rows; ++y) {
    const auto* f = backward_flow.ptr<cv::Vec2f>(y);
    for (int x = 0; x < backward_flow.cols; ++x) {
      if (!std::isfinite(f[x][0]) || !std::isfinite(f[x][1])) continue;
      const int side = x < half ? 0 : 1;
      sum[side] -= f[x][0];  // forward F = -B
      ++count[side];
    }
  }
  ParallaxScore s;
  s.left_px_s = count[0] > 0 ? sum[0] / count[0] / dt_s : 0.0;
  s.right_px_s = count[1] > 0 ? sum[1] / count[1] / dt_s : 0.0;
  s.divergence_px_s = s.right_px_s - s.left_px_s;
  s.pixels = count[0] + count[1];
  return s;
}

}  // namespace sg::vision
