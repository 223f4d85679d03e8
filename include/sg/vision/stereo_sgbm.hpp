#pragma once
/// Semi-global matching (DESIGN 2.1, matcher `sgbm`): OpenCV StereoSGBM, for comparison.
#include <opencv2/core.hpp>

#include "sg/core/params.hpp"

namespace sg::vision {

/// StereoSGBM (3-way mode, P1 = 8 b^2, P2 = 32 b^2 with b = block_size, OpenCV's suggested
/// penalties) on the whole image, without the speckle filter (filter_speckles does it). Not
/// row-tileable: its paths run along whole columns, so a tile's result depends on every row above
/// and below. The output rows `rows` are written from one whole-image match, so tiles stay
/// bit-identical to the whole image but each tile pays for the whole image: run sgbm with T = 1.
/// disp: CV_32F of the image size, px, multiples of 1/16; invalid -1.
void match_sgbm_rows(const cv::Mat& left, const cv::Mat& right, const core::BmParams& p,
                     cv::Mat& disp, cv::Range rows);

}  // namespace sg::vision
