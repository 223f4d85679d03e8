#pragma once
/// The pipeline's per-frame work, one frame at a time on the caller's thread: stereo matching
/// with params.bm (all rows, then the speckle filter), the depth edges and the optical flow to the
/// previous frame's left image in Stereo-Flow mode, then the detector's labelling, obstacles and
/// signals (vision::Detector::process). The same kernels and order as pipeline::run, so a stream
/// of frames gives the detections of run() over the same frames (which equal any W and T's).
/// Starts no threads; OpenCV's parallel loops inside the kernels may use their own.
#include <opencv2/core.hpp>

#include "sg/core/camera.hpp"
#include "sg/core/detection.hpp"
#include "sg/core/frame.hpp"
#include "sg/core/params.hpp"
#include "sg/vision/detector.hpp"

namespace sg::pipeline {

class SequentialDetector {
 public:
  /// params must be valid (core::validate, or pipeline::validate of the options holding them).
  SequentialDetector(const core::DetectorParams& params, const core::Camera& camera);

  /// Frames in stream order (increasing index). Throws core::InputError for a frame that is not
  /// a CV_8UC1 pair of equal sizes, or whose size differs from the camera's or earlier frames'.
  /// latency_ms is left 0.
  core::Detection process(const core::StereoFrame& frame);

  /// The last frame's disparity, CV_32F px (invalid < 0); empty before the first frame or for a
  /// detector without disparity (core::needs). A fresh map each frame: a share stays valid.
  const cv::Mat& disparity() const { return disparity_; }
  /// The last frame's backward flow to the previous left image, CV_32FC2 px; empty for the first
  /// frame and in modes without flow. A fresh map each frame.
  const cv::Mat& flow() const { return flow_; }

 private:
  core::DetectorParams params_;
  core::Camera camera_;
  vision::Detector detector_;
  cv::Mat previous_left_, disparity_, flow_;
};

}  // namespace sg::pipeline
