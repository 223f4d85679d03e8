#include "sg/eval/stereo_metrics.hpp"

#include <cmath>

namespace sg::eval {

StereoScores score_disparity(const cv::Mat& disparity, const cv::Mat& gt) {
  CV_Assert(disparity.type() == CV_32F && gt.type() == CV_32F && disparity.size() == gt.size());
  StereoScores s;
  long off1 = 0, off2 = 0, off4 = 0;
  double abs_sum = 0;
  for (int y = 0; y < gt.rows; ++y) {
    const float* g = gt.ptr<float>(y);
    const float* d = disparity.ptr<float>(y);
    for (int x = 0; x < gt.cols; ++x) {
      if (!(std::isfinite(g[x]) && g[x] > 0)) continue;
      ++s.gt_pixels;
      if (!(d[x] >= 0)) continue;
      ++s.matched;
      const double err = std::abs(static_cast<double>(d[x]) - g[x]);
      abs_sum += err;
      off1 += err > 1.0;
      off2 += err > 2.0;
      off4 += err > 4.0;
    }
  }
  if (s.gt_pixels == 0) return s;
  const double gt_n = static_cast<double>(s.gt_pixels);
  const long missing = s.gt_pixels - s.matched;
  s.density = s.matched / gt_n;
  s.dense_bad1 = 100.0 * (off1 + missing) / gt_n;
  s.dense_bad2 = 100.0 * (off2 + missing) / gt_n;
  s.dense_bad4 = 100.0 * (off4 + missing) / gt_n;
  if (s.matched > 0) {
    const double m = static_cast<double>(s.matched);
    s.bad1 = 100.0 * off1 / m;
    s.bad2 = 100.0 * off2 / m;
    s.bad4 = 100.0 * off4 / m;
    s.mae = abs_sum / m;
  }
  return s;
}

}  // namespace sg::eval
