#pragma once
/// Motion parallax (thesis 3.1.1, DESIGN 3.4, after the thesis' [36]): a monocular cue. Moving
/// towards a surface makes the flow diverge from the focus of expansion, so the horizontal flow
/// of the right half of the image points right and that of the left half left:
///   divergence = mean over the right half of F_x - mean over the left half of F_x,
/// with F the forward flow (previous frame to this one), in px/s. A uniform translation (a yaw of
/// the camera, a scene sliding past) cancels; an approach gives a positive value wherever the focus
/// of expansion lies, since F_x = k (x - x_foe) differs between the halves by k w / 2. The signal
/// fires above a threshold; the obstacle lies on the side whose flow is larger.
#include <opencv2/core.hpp>

namespace sg::vision {

struct ParallaxScore {
  double left_px_s = 0.0;   ///< mean forward F_x over the left half's finite flow, px/s
  double right_px_s = 0.0;  ///< the same over the right half
  double divergence_px_s = 0.0;  ///< right_px_s - left_px_s
  int pixels = 0;                ///< finite flow vectors counted
};

/// The score of a backward flow B (CV_32FC2, this frame to the previous one, so F = -B) over `dt_s`
/// seconds; columns x < width / 2 are the left half. Non-finite vectors are left out; a half with
/// none counts as 0. Throws core::InputError on a wrong type, an empty flow or dt_s <= 0.
ParallaxScore motion_parallax(const cv::Mat& backward_flow, double dt_s);

}  // namespace sg::vision
