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

/// Stereo mode: p is dangerous for gap k when D_i(p) and D_{i-k}(p) are valid, Z_i(p) <= z_max,
/// D_i - D_{i-k} >= min_delta_d_px, TTC = k*dt * D_{i-k} / (D_i - D_{i-k}) <= horizon, and (when
/// use_envelope_band) the point's Y lies in the envelope's band. A pixel dangerous for any gap
/// is dangerous; its TTC is the smallest over the gaps that flag it.
/// danger: CV_8U 0/255; ttc: CV_32F seconds, NaN where safe.
void label_stereo(const cv::Mat& disp, const std::vector<PastDisparity>& past,
                  const core::Camera& camera, const core::StereoLabelParams& p,
                  const core::Envelope& envelope, cv::Mat& danger, cv::Mat& ttc);

}  // namespace sg::vision
