#pragma once
/// The collector's labelling step around pure functions: owns the past disparity maps and the
/// hysteresis state; one Detection per frame, in frame order.
#include <deque>
#include <opencv2/core.hpp>

#include "sg/core/camera.hpp"
#include "sg/core/detection.hpp"
#include "sg/core/frame.hpp"
#include "sg/core/params.hpp"
#include "sg/vision/signals.hpp"

namespace sg::vision {

/// What the workers computed for one frame.
struct FrameMaps {
  cv::Mat disparity;  ///< CV_32F, px, invalid < 0
  cv::Mat flow;       ///< CV_32FC2 backward flow (Stereo-Flow mode), empty otherwise
};

class Detector {
 public:
  /// params must be valid (core::validate).
  Detector(const core::DetectorParams& params, const core::Camera& camera);
  /// Frames must arrive in order. The first frame (no history) is never dangerous.
  core::Detection process(const core::StereoFrame& frame, const FrameMaps& maps);

 private:
  core::DetectorParams params_;
  core::Camera camera_;
  std::deque<cv::Mat> past_;  ///< past_[0] = D_{i-1}, past_[1] = D_{i-2}, ...
  RegionHysteresis hysteresis_;
};

/// Computes the disparity for a frame with the configured matcher (whole image).
void compute_disparity(const core::StereoFrame& frame, const core::DetectorParams& params,
                       cv::Mat& disp);

}  // namespace sg::vision
