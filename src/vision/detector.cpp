#include "sg/vision/detector.hpp"

#include <algorithm>
#include <limits>

#include "sg/core/error.hpp"
#include "sg/vision/edge_margin.hpp"
#include "sg/vision/ego_motion.hpp"
#include "sg/vision/labelling.hpp"
#include "sg/vision/scene_flow.hpp"

namespace sg::vision {

Detector::Detector(const core::DetectorParams& params, const core::Camera& camera)
    : params_(params), camera_(camera), hysteresis_(params.signal) {
  const std::vector<int>& gaps =
      params_.mode == core::Mode::kStereoFlow ? params_.scene_flow.gaps : params_.stereo.gaps;
  if (!gaps.empty()) max_gap_ = std::max(1, *std::max_element(gaps.begin(), gaps.end()));
}

void Detector::label_flow(const FrameMaps& maps, cv::Mat& danger, cv::Mat& ttc, cv::Mat& velocity) {
  const cv::Mat& disp = maps.disparity;
  // Gap k needs D_{i-k} and B_i ... B_{i-k+1}: the current flow plus k - 1 stored ones.
  std::vector<const cv::Mat*> flows;
  if (!maps.flow.empty()) {
    flows.push_back(&maps.flow);
    for (const cv::Mat& f : flows_) flows.push_back(&f);
  }
  std::vector<const cv::Mat*> disps, edges;
  for (const cv::Mat& d : past_) disps.push_back(&d);
  for (const cv::Mat& e : past_edges_) edges.push_back(&e);
  const core::SceneFlowParams& sf = params_.scene_flow;
  mark_depth_edges(disp, sf.edge_margin_px, sf.edge_step_px, edges_);
  if (sf.keep_thin_structures)
    unmark_thin_structures(disp, sf.edge_margin_px, sf.edge_step_px, edges_);
  // The camera's own rotation over each gap: per-frame estimates chained, newest first.
  std::vector<cv::Matx33d> derotations;
  if (sf.compensate_rotation && !maps.flow.empty()) {
    frame_derotation_ = derotation(estimate_ego_motion(maps.flow, disp, camera_));
    cv::Matx33d chain = frame_derotation_;
    derotations.push_back(chain);
    for (const cv::Matx33d& m : derotations_) {
      chain = chain * m;
      derotations.push_back(chain);
    }
  }
  label_stereo_flow_window(disp, disps, flows, camera_, params_.envelope, sf,
                           camera_.frame_period(), danger, ttc, velocity, &edges_, &edges,
                           derotations.empty() ? nullptr : &derotations);
  if (sf.grow_into_edges)
    grow_danger_into_edges(disp, edges_, sf.edge_margin_px, sf.edge_step_px,
                           params_.signal.open_size, danger, ttc, velocity);
  if (params_.scene_flow.exclude_ground) {
    const GroundPlane plane = fit_ground_plane(disp, camera_, params_.scene_flow.ground);
    cv::Mat ground;
    mark_ground(disp, camera_, plane, params_.scene_flow.ground.tolerance_m, ground);
    danger.setTo(0, ground);
    ttc.setTo(std::numeric_limits<float>::quiet_NaN(), ground);
  }
}

core::Detection Detector::process(const core::StereoFrame& frame, const FrameMaps& maps) {
  const cv::Mat& disp = maps.disparity;
  if (disp.empty() || disp.type() != CV_32FC1)
    throw core::InputError("detector: the disparity map must be a non-empty CV_32F image");
  if (!past_.empty() && past_.front().size() != disp.size())
    throw core::InputError("detector: the disparity map changed size within a stream");

  const bool flow_mode = params_.mode == core::Mode::kStereoFlow;
  if (flow_mode && !maps.flow.empty() &&
      (maps.flow.type() != CV_32FC2 || maps.flow.size() != disp.size()))
    throw core::InputError("detector: the flow must be a CV_32FC2 map of the disparity's size");

  if (!past_index_.empty() && frame.index <= past_index_.front())
    throw core::InputError("detector: frames must arrive in increasing index order");
  // Stereo-Flow chains the flows of consecutive frames; after a dropped frame the chain (and the
  // past it refers to) starts afresh. Stereo mode measures each gap by frame indices instead.
  if (flow_mode && !past_index_.empty() && frame.index != past_index_.front() + 1) {
    past_.clear();
    past_index_.clear();
    past_edges_.clear();
    flows_.clear();
    derotations_.clear();
  }

  core::Detection det;
  det.frame = frame.index;
  det.time_s = frame.time_s;
  cv::Mat ttc, velocity;
  if (flow_mode) {
    label_flow(maps, det.danger, ttc, velocity);
  } else {
    std::vector<PastDisparity> past;
    for (int k : params_.stereo.gaps)
      if (k <= static_cast<int>(past_.size()))
        past.push_back({frame.index - past_index_[static_cast<size_t>(k - 1)],
                        &past_[static_cast<size_t>(k - 1)]});
    label_stereo(disp, past, camera_, params_.stereo, params_.envelope, det.danger, ttc);
  }
  det.obstacles = extract_obstacles(det.danger, disp, ttc, camera_, params_.signal, velocity);
  det.regions = hysteresis_.update(count_region_pixels(det.danger, params_.signal.region_columns));
  det.signal = std::any_of(det.regions.begin(), det.regions.end(),
                           [](const core::RegionSignal& r) { return r.fired; });
  det.severity = severity_of(det.signal, det.obstacles, params_.signal);
  det.steering = steering_hint(det.regions);

  past_.push_front(disp.clone());
  past_index_.push_front(frame.index);
  while (static_cast<int>(past_.size()) > max_gap_) {
    past_.pop_back();
    past_index_.pop_back();
  }
  if (flow_mode) {
    past_edges_.push_front(edges_.clone());
    while (static_cast<int>(past_edges_.size()) > max_gap_) past_edges_.pop_back();
    // The chain B_i, B_{i-1}, ... must be unbroken: a frame without flow starts it afresh.
    if (maps.flow.empty()) {
      flows_.clear();
      derotations_.clear();
    } else {
      flows_.push_front(maps.flow.clone());
      derotations_.push_front(frame_derotation_);
    }
    while (static_cast<int>(flows_.size()) > max_gap_ - 1) flows_.pop_back();
    while (static_cast<int>(derotations_.size()) > max_gap_ - 1) derotations_.pop_back();
  }
  return det;
}

}  // namespace sg::vision
