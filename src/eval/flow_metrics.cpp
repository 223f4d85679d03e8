#include "sg/eval/flow_metrics.hpp"

#include <cmath>

#include "sg/core/error.hpp"

namespace sg::eval {

FlowAccuracy flow_accuracy(const cv::Mat& flow, const cv::Mat& gt) {
  if (flow.type() != CV_32FC2 || gt.type() != CV_32FC2)
    throw core::InputError("flow accuracy: flow and ground truth must be CV_32FC2");
  if (flow.size() != gt.size())
    throw core::InputError("flow accuracy: flow is " + std::to_string(flow.cols) + "x" +
                           std::to_string(flow.rows) + " but ground truth is " +
                           std::to_string(gt.cols) + "x" + std::to_string(gt.rows));
  constexpr float kUnknown = 1e9f;
  double sum = 0.0;
  long bad = 0, valid = 0;
  for (int y = 0; y < gt.rows; ++y) {
    const cv::Vec2f* g = gt.ptr<cv::Vec2f>(y);
    const cv::Vec2f* f = flow.ptr<cv::Vec2f>(y);
    for (int x = 0; x < gt.cols; ++x) {
      const float gu = g[x][0], gv = g[x][1];
      if (!(std::abs(gu) < kUnknown) || !(std::abs(gv) < kUnknown)) continue;  // NaN too
      float u = f[x][0], v = f[x][1];
      if (!std::isfinite(u) || !std::isfinite(v)) u = v = 0.0f;
      const double e = std::hypot(static_cast<double>(u) - gu, static_cast<double>(v) - gv);
      sum += e;
      bad += e > 3.0 ? 1 : 0;
      ++valid;
    }
  }
  FlowAccuracy a;
  a.valid_pixels = valid;
  if (valid > 0) {
    a.epe = sum / static_cast<double>(valid);
    a.bad3_percent = 100.0 * static_cast<double>(bad) / static_cast<double>(valid);
  }
  return a;
}

}  // namespace sg::eval
