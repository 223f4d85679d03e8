#pragma once
/// Pixel labelling (DESIGN 3.1): safe or dangerous, with a per-pixel time to contact.
#include <opencv2/core.hpp>
#include <vector>

#include "sg/core/camera.hpp"
#include "sg/core/params.hpp"

namespace sg::vision {

/// A past disparity map and how many frames ago it was taken.
struct PastDisparity {
  int gap = 1;           ///< k >= 1: D_{i-k}
  const cv::Mat* disp;   ///< CV_32F, invalid < 0
};

/// Stereo mode: p is dangerous for gap k when D_i(p) and D_{i-k}(p) are valid (> 0: a zero
/// disparity is a point at infinity), Z_i(p) <= z_max, D_i - D_{i-k} >= min_delta_d_px,
/// D_i <= max_growth * D_{i-k} (when max_growth > 0),
/// its time to contact TTC = k*dt * D_{i-k} / (D_i - D_{i-k}) * (Z_i - z_contact) / Z_i (the time
/// to reach the envelope's contact depth, dt = 1/fps) <= envelope.horizon_s, and (when
/// use_envelope_band) the point's Y = (y - cy) * Z_i / f lies in [y_top_m, y_bottom_m]. A pixel
/// dangerous for any gap is dangerous; its TTC is that of the longest gap that flags it (for a
/// constant approach every gap estimates the same TTC; the longest averages the most noise).
/// `past` may be empty (nothing is dangerous); every past map has the size of `disp`.
/// danger: CV_8U 0/255; ttc: CV_32F seconds, NaN where safe (both allocated if needed).
void label_stereo(const cv::Mat& disp, const std::vector<PastDisparity>& past,
                  const core::Camera& camera, const core::StereoLabelParams& p,
                  const core::Envelope& envelope, cv::Mat& danger, cv::Mat& ttc);

}  // namespace sg::vision
