#pragma once
/// The baseline of the real-recording tables (DESIGN 4.1, docs/real-recordings.md): what a student
/// writes first. StereoSGBM on the whole pair, then the median disparity of the central quarter
/// of the image gives one distance per frame. Pure functions, no threads, no state.
#include <opencv2/core.hpp>
#include <optional>

#include "sg/core/camera.hpp"
#include "sg/core/params.hpp"

namespace sg::vision {

/// The central quarter of an image: half its width and half its height, centred
/// (x from width/4 to width/4 + width/2, likewise y).
cv::Rect central_box(cv::Size size);

/// StereoSGBM as a student sets it up: 3-way mode, disparities 0 .. num_disparities - 1 and the
/// block size of `bm` (other fields of `bm` are not used), P1 = 8 b^2 and P2 = 32 b^2 (OpenCV's
/// suggested penalties for one channel, b = block size), uniqueness 10 %, speckle window 100 px
/// with range 2 px, left-right tolerance 1 px, pre-filter cap 63 (the values OpenCV's
/// documentation and its stereo_match sample suggest).
/// left, right: CV_8UC1 of the same size. disp: CV_32F, px (multiples of 1/16), invalid -1.
void match_sgbm_baseline(const cv::Mat& left, const cv::Mat& right, const core::BmParams& bm,
                         cv::Mat& disp);

struct CentralMedian {
  cv::Rect box;                        ///< the central quarter, left-image px
  int valid_px = 0;                    ///< pixels of the box with a disparity > 0
  std::optional<double> disparity_px;  ///< their median, px; empty when none
  std::optional<double> distance_m;    ///< f*B / median disparity, m; empty when none
};

/// Median of the disparities > 0 of `disp` (CV_32F, px; <= 0 = invalid or infinitely far) inside
/// central_box(disp.size()), and its distance for `camera`.
CentralMedian central_median(const cv::Mat& disp, const core::Camera& camera);

}  // namespace sg::vision
