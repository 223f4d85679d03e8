#pragma once
/// Stereo accuracy against ground truth (Middlebury / KITTI conventions).
#include <opencv2/core.hpp>

namespace sg::eval {

/// Scores over the GT-valid pixels (GT > 0 and finite). "Sparse" figures count only the pixels
/// the matcher also gave (output >= 0); "dense" figures count a missing output as bad.
struct StereoScores {
  long gt_pixels = 0;                   ///< GT-valid pixels
  long matched = 0;                     ///< GT-valid pixels with a valid output
  double density = 0;                   ///< matched / gt_pixels, fraction 0..1
  double bad1 = 0, bad2 = 0, bad4 = 0;  ///< sparse: % of matched off by > 1/2/4 px
  double dense_bad1 = 0, dense_bad2 = 0, dense_bad4 = 0;  ///< dense: % of gt_pixels
  double mae = 0;  ///< mean |output - GT| over matched pixels, px
};

/// disparity: CV_32F px, invalid < 0. gt: CV_32F px, 0 or non-finite = unknown. Same size (else
/// cv::Exception).
StereoScores score_disparity(const cv::Mat& disparity, const cv::Mat& gt);

}  // namespace sg::eval
