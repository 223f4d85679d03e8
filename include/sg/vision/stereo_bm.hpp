#pragma once
/// Block-matching stereo (DESIGN 2.1, matcher `bm`): OpenCV StereoBM.
#include <opencv2/core.hpp>

#include "sg/core/params.hpp"

namespace sg::vision {

/// Rows a tile of output rows [r0, r1) must read: [r0 - h, r1 + h) clipped to the image, with
/// h = block_size / 2 + 1 (the block plus the 3x3 x-Sobel prefilter), the start rounded down to an
/// even row (the prefilter works on row pairs and blanks the last row of an odd-height input), and
/// widened to at least block_size + 1 rows (StereoBM's minimum). Range::all() -> [0, height).
cv::Range bm_input_rows(cv::Range rows, const core::BmParams& p, int height);

/// Raw block matching of output rows `rows` (cv::Range::all() = whole image), without the speckle
/// filter, so that tiles computed separately and stitched are bit-identical to the whole image
/// (and independent of OpenCV's thread count). The prefilter is x-Sobel, OpenCV's default.
/// left/right: CV_8UC1, same size. disp: CV_32F of the full image size (allocated if needed), px;
/// only `rows` are written (so tiles may share one preallocated map); disparities are multiples of
/// 1/16 px in [min_disparity, min_disparity + num_disparities); invalid pixels are -1.
void match_bm_rows(const cv::Mat& left, const cv::Mat& right, const core::BmParams& p,
                   cv::Mat& disp, cv::Range rows);

/// Speckle filter over the whole disparity map (in place): cv::filterSpeckles on the 1/16 px
/// fixed-point map, speckle_window px, speckle_range px (x16). Removed pixels become -1.
void filter_speckles(cv::Mat& disp, const core::BmParams& p);

/// Whole-image matching: match_bm_rows over all rows, then filter_speckles.
void match_bm(const cv::Mat& left, const cv::Mat& right, const core::BmParams& p, cv::Mat& disp);

}  // namespace sg::vision
