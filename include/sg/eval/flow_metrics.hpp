#pragma once
/// Optical-flow accuracy against ground truth (docs/stereo-flow.md; Middlebury conventions).
#include <opencv2/core.hpp>

namespace sg::eval {

struct FlowAccuracy {
  double epe = 0.0;           ///< mean end-point error |flow - gt| over GT-valid pixels, px
  double bad3_percent = 0.0;  ///< percentage of GT-valid pixels whose end-point error > 3 px
  long valid_pixels = 0;      ///< GT-valid pixels counted (0: epe and bad3_percent are 0)
};

/// Compares an estimated flow with a ground-truth flow, both CV_32FC2 (u, v) px of the same size
/// and the same direction (InputError otherwise). A GT pixel is valid when both components are
/// finite and |u|, |v| < 1e9 (Middlebury "unknown"). A non-finite estimate counts as zero flow.
FlowAccuracy flow_accuracy(const cv::Mat& flow, const cv::Mat& gt);

}  // namespace sg::eval
