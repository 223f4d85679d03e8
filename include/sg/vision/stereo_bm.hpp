#pragma once
/// Block-matching stereo (DESIGN 2.1, matcher `bm`): OpenCV StereoBM.
#include <opencv2/core.hpp>

#include "sg/core/params.hpp"

namespace sg::vision {

/// Rows a tile of output rows [r0, r1) must read: [r0 - h, r1 + h) clipped, h = block_size / 2
/// (plus what the prefilter needs).
cv::Range bm_input_rows(cv::Range rows, const core::BmParams& p, int height);

/// Raw block matching of output rows `rows` (cv::Range::all() = whole image), without the speckle
/// filter, so that tiles computed separately and stitched are bit-identical to the whole image.
/// left/right: CV_8UC1, same size. disp: CV_32F of the full image size (allocated if needed), px;
/// only `rows` are written; invalid pixels < 0.
void match_bm_rows(const cv::Mat& left, const cv::Mat& right, const core::BmParams& p,
                   cv::Mat& disp, cv::Range rows);

/// Speckle filter over the whole disparity map (in place; invalid pixels stay < 0).
void filter_speckles(cv::Mat& disp, const core::BmParams& p);

/// Whole-image matching: match_bm_rows over all rows, then filter_speckles.
void match_bm(const cv::Mat& left, const cv::Mat& right, const core::BmParams& p, cv::Mat& disp);

}  // namespace sg::vision
