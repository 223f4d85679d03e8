#pragma once
/// The workers' two tasks on one frame (DESIGN 1): stereo matching (SM) and optical flow (OF),
/// each callable on a row range so that a caller may split a frame into tiles. Pure functions; the
/// caller owns the outputs and decides about threads.
#include <opencv2/core.hpp>

#include "sg/core/frame.hpp"
#include "sg/core/params.hpp"

namespace sg::vision {

/// Throws core::InputError unless left/right are non-empty CV_8UC1 images of the same size.
void check_frame(const core::StereoFrame& frame);

/// SM on output rows `rows` with params.bm.matcher (bm, sgbm, fast or longseq): raw matching
/// without the speckle filter (sgbm is not tileable: each tile matches the whole image, see
/// stereo_sgbm.hpp). disp must be allocated as CV_32F of the frame size before tiles run
/// (allocate_maps). Tiles stitched are bit-identical to one call over all rows.
void disparity_rows(const core::StereoFrame& frame, const core::DetectorParams& params,
                    cv::Mat& disp, cv::Range rows);
/// SM finishing step over the whole map, after all tiles: the speckle filter, then, with
/// params.bm.coarse_fill and a row matcher (bm, fast), the holes filled from the half-size pair
/// (vision/coarse_fill.hpp).
void disparity_finish(const core::StereoFrame& frame, const core::DetectorParams& params,
                      cv::Mat& disp);

/// OF on output rows `rows`: backward flow from `current` to `previous` (left images). flow must
/// be allocated as CV_32FC2 of the frame size. With tiles the result differs near the cuts within
/// the tolerance stated in vision/flow.hpp (pyramids).
void flow_rows(const cv::Mat& current, const cv::Mat& previous,
               const core::DetectorParams& params, cv::Mat& flow, cv::Range rows);

/// Allocates disp (CV_32F) and, when `with_flow`, flow (CV_32FC2) at `size`.
void allocate_maps(cv::Size size, bool with_flow, cv::Mat& disp, cv::Mat& flow);

}  // namespace sg::vision
