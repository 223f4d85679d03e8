#pragma once
/// The left band of a stereo pair (DESIGN 2.1): the columns x < min_disparity + num_disparities
/// - 1 + block_size / 2 where a block matcher with the full range leaves every pixel invalid
/// (its search would leave the right image). A point there is still seen by both cameras when
/// its disparity is below x; with a range of 224 px (a wide baseline whose contact depth is
/// near) the band is a third of a 640-px image, blind to whatever enters from the left.
#include <opencv2/core.hpp>

#include "sg/core/params.hpp"

namespace sg::vision {

/// A matcher of output rows, as match_fast_rows: writes `rows` of disp (CV_32F of the image
/// size, allocated if needed), -1 where invalid, and leaves the band invalid.
using RowMatcher = void (*)(const cv::Mat& left, const cv::Mat& right, const core::BmParams& p,
                            cv::Mat& disp, cv::Range rows);

/// Fills the left band of `rows` of disp with `match` run again, strip by strip: the 16 columns
/// from min_disparity + n - 1 + h are matched with the range n (n = 16, 32, .. below
/// num_disparities) on the image cut one column past the blocks that reach them (so that every
/// prefilter reads inside the cut as in the whole image). A strip's winner at its largest
/// disparity is dropped (the true one may lie beyond the range). With lr_max_diff >= 0, each band
/// match must also agree within lr_max_diff with the full-range match of the right pixel it
/// points to. Every output pixel is a function of the pair alone, so tiles stitched are
/// bit-identical to one call. Columns left of min_disparity + 15 + h stay invalid; disp right
/// of the band is untouched.
void match_left_band_rows(RowMatcher match, const cv::Mat& left, const cv::Mat& right,
                          const core::BmParams& p, cv::Mat& disp, cv::Range rows);

}  // namespace sg::vision
