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
  /// params must be valid (core::validate). Throws core::InputError for Mode::kStereoFlow (not
  /// implemented yet).
  Detector(const core::DetectorParams& params, const core::Camera& camera);
  /// Frames must arrive in order. Labels D_i against the past maps of every configured gap k for
  /// which k frames of history exist (so the first frame is never dangerous), then obstacles,
  /// region counts, hysteresis, severity and steering. Fills frame and time_s from `frame`,
  /// danger = the cleaned mask; leaves latency_ms to the caller. Throws core::InputError when the
  /// disparity is not a non-empty CV_32F map or changes size within the stream.
  core::Detection process(const core::StereoFrame& frame, const FrameMaps& maps);

 private:
  core::DetectorParams params_;
  core::Camera camera_;
  std::deque<cv::Mat> past_;  ///< past_[0] = D_{i-1}, past_[1] = D_{i-2}, ...
  RegionHysteresis hysteresis_;
};

/// Computes the disparity for a frame with the configured matcher (whole image: match_bm).
/// Throws core::InputError when left/right are not CV_8UC1 of the same size.
void compute_disparity(const core::StereoFrame& frame, const core::DetectorParams& params,
                       cv::Mat& disp);

}  // namespace sg::vision
