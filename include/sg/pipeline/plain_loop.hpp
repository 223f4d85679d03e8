#pragma once
/// The loop a user would write instead of the pipeline (DESIGN 8): one frame at a time, OpenCV's
/// StereoBM, DIS ultrafast in Stereo-Flow mode, then the detector's labelling, obstacles and
/// signals. No skeleton, no threads of its own: OpenCV's parallel loops run with whatever thread
/// count the process has (cv::setNumThreads). The baseline rows of `bench` and the whole-process
/// baseline (the plain_loop program, src/apps/plain_loop.cpp) both run it.
#include <opencv2/calib3d.hpp>
#include <opencv2/video/tracking.hpp>

#include "sg/core/camera.hpp"
#include "sg/core/detection.hpp"
#include "sg/core/frame.hpp"
#include "sg/core/params.hpp"
#include "sg/vision/detector.hpp"

namespace sg::pipeline {

class PlainLoop {
 public:
  /// params must be valid (core::validate); params.bm sets StereoBM (the matcher field is
  /// ignored: the plain loop is StereoBM), params.mode what it computes (core::needs).
  PlainLoop(const core::DetectorParams& params, const core::Camera& camera);

  /// Frames in stream order: disparity, flow to the previous frame's left image (Stereo-Flow,
  /// from the second frame on), labelling and signals.
  core::Detection process(const core::StereoFrame& frame);

 private:
  core::Needs needs_;
  cv::Ptr<cv::StereoBM> bm_;
  cv::Ptr<cv::DISOpticalFlow> dis_;
  vision::Detector detector_;
  cv::Mat previous_left_, disp16_;
};

/// The labelling a user writes first: `params` with one frame gap (k = 1) in both modes, instead
/// of the chains over several gaps of the defaults.
core::DetectorParams naive_labelling(core::DetectorParams params);

}  // namespace sg::pipeline
