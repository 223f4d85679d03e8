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
  /// CV_32FC2 backward flow B_i from L_i to L_{i-1} (Stereo-Flow mode), empty for the first
  /// frame and in Stereo mode.
  cv::Mat flow;
};

class Detector {
 public:
  /// params must be valid (core::validate).
  Detector(const core::DetectorParams& params, const core::Camera& camera);
  /// Frames must arrive in order. Labels D_i against the past maps of every configured gap k for
  /// which k frames of history exist (so the first frame is never dangerous): Stereo mode with
  /// label_stereo (params.stereo), Stereo-Flow mode with label_stereo_flow_window
  /// (params.scene_flow, dt = camera.frame_period()), whose gap k also needs the flows of the
  /// last k frames (an empty maps.flow restarts the flow history); with scene_flow.
  /// compensate_rotation the camera's rotation is estimated from each flow (estimate_ego_motion)
  /// and removed over every gap; keep_thin_structures and grow_into_edges adjust the depth-edge
  /// margin (vision/edge_margin.hpp). Then, in Stereo-Flow mode
  /// with scene_flow.exclude_ground, dangerous pixels on or below a ground plane fitted to D_i
  /// are cleared; then obstacles (with the mean 3D velocity in Stereo-Flow mode), region counts,
  /// hysteresis, severity and steering. Fills frame and time_s from `frame`, danger = the cleaned
  /// mask; leaves latency_ms to the caller. Throws core::InputError when the disparity is not a
  /// non-empty CV_32F map, when a non-empty flow is not CV_32FC2 of its size, or when the size
  /// changes within the stream.
  core::Detection process(const core::StereoFrame& frame, const FrameMaps& maps);

 private:
  /// Stereo-Flow labelling of D_i with maps.flow and the history; fills danger, ttc, velocity.
  void label_flow(const FrameMaps& maps, cv::Mat& danger, cv::Mat& ttc, cv::Mat& velocity);

  core::DetectorParams params_;
  core::Camera camera_;
  int max_gap_ = 1;           ///< longest gap of the active mode
  std::deque<cv::Mat> past_;  ///< past_[0] = D_{i-1}, past_[1] = D_{i-2}, ...
  /// Frame index of each past_ map. Frame indices count camera frames, dropped ones included, so
  /// a paced run that dropped frames still gets the right time span for each gap.
  std::deque<int> past_index_;
  /// Stereo-Flow: flows_[0] = B_{i-1}, flows_[1] = B_{i-2}, ... (consecutive, no gap).
  std::deque<cv::Mat> flows_;
  /// Stereo-Flow: depth-edge masks (mark_depth_edges) of D_i (edges_) and of past_ (same order).
  cv::Mat edges_;
  std::deque<cv::Mat> past_edges_;
  /// Stereo-Flow with compensate_rotation: derotation of each stored flow's frame
  /// (derotations_[0] belongs to flows_[0]), and of the current frame.
  std::deque<cv::Matx33d> derotations_;
  cv::Matx33d frame_derotation_ = cv::Matx33d::eye();
  RegionHysteresis hysteresis_;
};

}  // namespace sg::vision
