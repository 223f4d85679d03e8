#pragma once
/// The simulator's motion blur: what an exposure of `share` frame intervals does to an image
/// whose pixels move by `flow` (backward flow of one frame, px) while the shutter is open, and the
/// sensor noise added after it.
#include <opencv2/core.hpp>

namespace sg::sim {

/// Replaces `gray` (CV_8UC1, rendered without noise) with the mean of n samples of it, each taken
/// by bilinear interpolation at p + flow(p) * share * (1/2 - k / (n - 1)), k = 0..n-1, then adds
/// `noise` (CV_32FC1, or empty), rounding and saturating to 8 bits. n is 2..12, one sample per
/// pixel of the longest displacement. The samples are cv::remap's (INTER_LINEAR,
/// BORDER_REPLICATE, positions rounded to 1/32 px), taken in one pass over the rows in parallel;
/// the output equals motion_blur_reference's byte for byte (test).
void motion_blur(cv::Mat& gray, const cv::Mat& flow, double share, const cv::Mat& noise);

/// The reference of motion_blur: one cv::remap per sample with a float map. Tests only.
void motion_blur_reference(cv::Mat& gray, const cv::Mat& flow, double share, const cv::Mat& noise);

}  // namespace sg::sim
