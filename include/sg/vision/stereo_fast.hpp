#pragma once
/// Our own SIMD block matcher (DESIGN 2.1, matcher `fast`), written with Google Highway and
/// dispatched at run time to the best instruction set of the CPU (SSE4, AVX2, AVX-512), plus its
/// plain scalar reference, which it equals bit for bit.
///
/// Algorithm, per output pixel (x, y) and disparity d in [min_disparity, min_disparity +
/// num_disparities): the cost of a pixel pair is the absolute difference of the x-Sobel
/// prefiltered images (StereoBM's prefilter, clipped to +-prefilter_cap) or the Hamming distance
/// of 5x5 census signatures; costs are summed over a block_size x block_size block (integers,
/// incremental box sums); the smallest sum wins (on ties the largest disparity, as StereoBM: the
/// nearer surface). A pixel is invalid when its
/// block's texture (sum of |prefiltered|) is below texture_threshold, when another disparity
/// further than 1 px away costs at most (100 + uniqueness_ratio) % of the winner, or, with
/// lr_max_diff >= 0, when the right image's winner differs by more than lr_max_diff px. Sub-pixel
/// refinement as StereoBM (subpixel_disparity16). Like StereoBM, the pixels whose block or whose
/// search range leaves the image are invalid: x < min_disparity + num_disparities - 1 + h,
/// x >= width - h, y < h, y >= height - h, with h = block_size / 2.
#include <opencv2/core.hpp>
#include <string>

#include "sg/core/params.hpp"

namespace sg::vision {

/// Matches output rows `rows` (cv::Range::all() = whole image) with the `fast` matcher, without
/// the speckle filter (filter_speckles does it over the stitched map). Every output pixel is a
/// function of the whole input images, so tiles stitched are bit-identical to one call.
/// left/right: CV_8UC1, same size, may be non-continuous ROIs. disp: CV_32F of the image size
/// (allocated if needed), px, multiples of 1/16 px; only `rows` are written; invalid pixels -1.
/// Assumes valid params (core::validate): block_size^2 * max pixel cost must fit 16 bits.
void match_fast_rows(const cv::Mat& left, const cv::Mat& right, const core::BmParams& p,
                     cv::Mat& disp, cv::Range rows);

/// The plain scalar reference of match_fast_rows (naive block sums, no SIMD): same output, bit
/// for bit. Slow (O(width * height * num_disparities * block_size^2)); for tests.
void match_fast_reference(const cv::Mat& left, const cv::Mat& right, const core::BmParams& p,
                          cv::Mat& disp, cv::Range rows);

/// Name of the instruction set match_fast_rows dispatches to now (e.g. "AVX3", "AVX2", "SSE4").
std::string fast_matcher_target();

/// Sub-pixel disparity as StereoBM computes it, in 1/16 px: winner d (integer, px, relative or
/// absolute) with block costs c_minus at d - 1, c0 at d, c_plus at d + 1 (c0 the smallest). The
/// one place both the SIMD matcher and its reference refine. Integer arithmetic, exact.
inline int subpixel_disparity16(int d, int c_minus, int c0, int c_plus) {
  // Fit a V through the three costs: the offset (c_minus - c_plus) / denom lies in [-1/2, 1/2]
  // px. Truncating division, then round to the nearest 1/16 px, as OpenCV does.
  const int diff = c_minus - c_plus;
  const int denom = c_minus + c_plus - 2 * c0 + (diff < 0 ? -diff : diff);
  const int offset256 = denom != 0 ? diff * 256 / denom : 0;
  return (d * 256 + offset256 + 15) >> 4;
}

}  // namespace sg::vision
