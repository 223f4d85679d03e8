#pragma once
/// Matches on periodic texture dropped (DESIGN 2.1, `stereo.periodic_ratio`). A block matcher
/// compares costs at whole-pixel disparities. On a texture that repeats along the row every p px
/// (stripes, tiles, a fence, a chessboard) the disparities d, d + p, d + 2p ... all fit, and the
/// one that wins is whichever lands nearest a whole pixel, not the true one: the uniqueness
/// ratio cannot tell them apart, and the left-right check agrees with the same wrong one. On a
/// striped wall seen by a turning walker (random suite seed 1111) half of the matched pixels
/// were wrong by whole periods, and read as near surfaces rushing at the camera.
#include <opencv2/core.hpp>

#include "sg/core/params.hpp"

namespace sg::vision {

/// CV_8U mask of `left` (CV_8UC1): 255 where the matcher's block repeats along its row. With P
/// the row's gradient L(x + 1) - L(x - 1) clipped to +-p.prefilter_cap (the matcher's prefilter
/// without its vertical smoothing) and C_s the sum over the block of |P(x) - P(x - s)|, a block
/// repeats when min C_s over 2 <= s < min(p.num_disparities, width / 2) is below
/// p.periodic_ratio * C_1: shifted by a whole period it matches itself better
/// than shifted by one pixel (which bounds what a sub-pixel misalignment of the true match
/// costs). A smooth texture has C_s growing with s; noise has C_s about C_1 for every s.
/// C_s is summed over 4 x 4 cells (every other row) and the cells a block covers; a pixel takes
/// its cell's verdict. All zero when p.periodic_ratio is 0. vision::disparity_finish drops the
/// marked pixels' matches.
cv::Mat periodic_mask(const cv::Mat& left, const core::BmParams& p);

/// periodic_mask's scalar reference, pixel by pixel and cell by cell: the same mask, slower
/// (tests compare the two).
cv::Mat periodic_mask_reference(const cv::Mat& left, const core::BmParams& p);

}  // namespace sg::vision
