#include "sg/pipeline/sequential.hpp"

#include <string>

#include "sg/core/error.hpp"
#include "sg/vision/frame_kernels.hpp"

namespace sg::pipeline {

SequentialDetector::SequentialDetector(const core::DetectorParams& params,
                                       const core::Camera& camera)
    : params_(params), camera_(camera), detector_(params, camera) {}

core::Detection SequentialDetector::process(const core::StereoFrame& frame) {
  vision::check_frame(frame);
  if (frame.left.cols != camera_.width || frame.left.rows != camera_.height) {
    throw core::InputError("frame " + std::to_string(frame.index) + " is " +
                           std::to_string(frame.left.cols) + "x" + std::to_string(frame.left.rows) +
                           ", the camera " + std::to_string(camera_.width) + "x" +
                           std::to_string(camera_.height));
  }
  const core::Needs need = core::needs(params_.mode);
  vision::FrameMaps maps;
  if (need.disparity) {
    vision::allocate_maps(frame.left.size(), false, maps.disparity, maps.flow);
    vision::disparity_rows(frame, params_, maps.disparity, cv::Range::all());
    vision::disparity_finish(frame, params_, maps.disparity);
    if (params_.mode == core::Mode::kStereoFlow) {
      vision::depth_edges(params_, maps.disparity, maps.edges);
    }
  }
  if (need.flow && !previous_left_.empty()) {
    maps.flow.create(frame.left.size(), CV_32FC2);
    vision::flow_rows(frame.left, previous_left_, params_, maps.flow, cv::Range::all());
  }
  maps.left = frame.left;
  disparity_ = maps.disparity;
  flow_ = maps.flow;
  core::Detection d = detector_.process(frame, maps);
  previous_left_ = frame.left;
  return d;
}

}  // namespace sg::pipeline
