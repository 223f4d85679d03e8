#pragma once
// Scalar pieces shared by the fast matcher (stereo_fast.cpp) and its reference
// (stereo_fast_reference.cpp): the per-pixel transforms that precede matching. Internal header.
#include <cstdint>
#include <opencv2/core.hpp>

namespace sg::vision::fast_detail {

/// Census window radius: 5x5, 24 bits per signature.
constexpr int kCensusRadius = 2;
/// Invalid marker of the 1/16 px fixed-point disparities the kernels write.
constexpr std::int16_t kInvalid16 = INT16_MIN;

/// StereoBM's x-Sobel prefilter over image rows [r0, r1): value = clamp(Sobel_x, -cap, cap) + cap,
/// in [0, 2 cap]; borders as StereoBM (rows reflected, first and last columns = cap, and the last
/// row = cap when the height is odd: StereoBM filters rows in pairs). out: CV_8U,
/// (r1 - r0) x width.
void prefilter_rows(const cv::Mat& img, int cap, int r0, int r1, cv::Mat& out);

/// 5x5 census signatures over image rows [r0, r1): bit k set when neighbour k (row-major, centre
/// skipped) is darker than the centre; replicated border. out: CV_32S holding the 24-bit codes.
void census_rows(const cv::Mat& img, int r0, int r1, cv::Mat& out);

/// Converts the kernels' 1/16 px disparities (kInvalid16 = invalid) of `rows16` into disp rows
/// starting at y0, as px (invalid = -1).
void store_disparity16(const cv::Mat& rows16, int y0, cv::Mat& disp);

}  // namespace sg::vision::fast_detail
