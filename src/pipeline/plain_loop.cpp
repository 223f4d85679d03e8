#include "sg/pipeline/plain_loop.hpp"

namespace sg::pipeline {

PlainLoop::PlainLoop(const core::DetectorParams& params, const core::Camera& camera)
    : needs_(core::needs(params.mode)),
      bm_(cv::StereoBM::create(params.bm.num_disparities, params.bm.block_size)),
      dis_(cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_ULTRAFAST)),
      detector_(params, camera) {
  bm_->setPreFilterCap(params.bm.prefilter_cap);
  bm_->setTextureThreshold(params.bm.texture_threshold);
  bm_->setUniquenessRatio(params.bm.uniqueness_ratio);
  bm_->setSpeckleWindowSize(params.bm.speckle_window);
  bm_->setSpeckleRange(params.bm.speckle_range * 16);
  bm_->setDisp12MaxDiff(params.bm.lr_max_diff);
}

core::Detection PlainLoop::process(const core::StereoFrame& frame) {
  vision::FrameMaps maps;  // fresh maps: the detector keeps them in its history
  if (needs_.disparity) {
    bm_->compute(frame.left, frame.right, disp16_);
    disp16_.convertTo(maps.disparity, CV_32F, 1.0 / 16);
  }
  maps.left = frame.left;
  if (needs_.flow && !previous_left_.empty()) dis_->calc(frame.left, previous_left_, maps.flow);
  previous_left_ = frame.left;
  vision::LabelJob job = detector_.prepare(frame, std::move(maps));
  job.run(cv::Range::all());
  return detector_.finish(frame, job);
}

core::DetectorParams naive_labelling(core::DetectorParams params) {
  params.stereo.gaps = {1};
  params.scene_flow.gaps = {1};
  return params;
}

}  // namespace sg::pipeline
