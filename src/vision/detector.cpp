#include "sg/vision/detector.hpp"

#include <algorithm>
#include <limits>

#include "sg/core/error.hpp"
#include "sg/vision/edge_margin.hpp"
#include "sg/vision/ego_motion.hpp"
#include "sg/vision/labelling.hpp"
#include "sg/vision/segment_motion.hpp"
#include "sg/vision/surveyed.hpp"

namespace sg::vision {

void depth_edges(const core::DetectorParams& params, const cv::Mat& disparity, cv::Mat& edges) {
  const core::SceneFlowParams& sf = params.scene_flow;
  mark_depth_edges(disparity, sf.edge_margin_px, sf.edge_step_px, edges);
  if (sf.keep_thin_structures)
    unmark_thin_structures(disparity, sf.edge_margin_px, sf.edge_step_px, edges);
}

void LabelJob::run_surveyed() {
  const core::DetectorParams& p = *params_;
  const cv::Size size = disparity_.size();
  switch (mode_) {
    case core::Mode::kMotionParallax:
      if (span_s_ > 0)
        label_motion_parallax(flows_.front(), span_s_, p.motion_parallax, p.signal.min_area_px,
                              p.envelope.horizon_s, danger_, ttc_);
      break;
    case core::Mode::kRelativeSize:
      if (span_s_ > 0)
        label_relative_size(earlier_left_, left_, span_s_, p.relative_size, p.envelope.horizon_s,
                            danger_, ttc_);
      break;
    case core::Mode::kElevationMap:
      label_elevation_map(disparity_, *camera_, p.envelope, p.elevation, p.proximity, danger_,
                          ttc_);
      break;
    case core::Mode::kLongSeq:
      label_proximity(disparity_, cv::Mat(), *camera_, p.envelope, p.proximity, danger_, ttc_);
      break;
    case core::Mode::kSceneFlowSeg:
      if (span_s_ > 0)
        label_sceneflow_seg(left_, disparity_, past_.front(), flows_.front(), span_s_, *camera_,
                            p.envelope, p.sceneflow_seg, p.signal.min_area_px, danger_, ttc_,
                            velocity_);
      break;
    case core::Mode::kStereo:
    case core::Mode::kStereoFlow:
      break;
  }
  // Nothing to compare with yet: nothing is dangerous.
  if (danger_.empty()) {
    danger_ = cv::Mat::zeros(size, CV_8U);
    ttc_ = cv::Mat(size, CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  }
}

void LabelJob::run(cv::Range rows) {
  const core::DetectorParams& p = *params_;
  if (core::is_surveyed(mode_)) {
    run_surveyed();
    return;
  }
  if (!flow_mode_) {
    std::vector<PastDisparity> past;
    for (size_t j = 0; j < past_.size(); ++j) past.push_back({steps_[j], &past_[j]});
    label_stereo(disparity_, past, *camera_, p.stereo, p.envelope, danger_, ttc_);
    return;
  }
  std::vector<const cv::Mat*> flows;
  for (const cv::Mat& f : flows_) flows.push_back(&f);
  std::vector<GapSource> gaps;
  for (size_t j = 0; j < past_.size(); ++j)
    gaps.push_back({steps_[j], &past_[j], &past_edges_[j], spans_s_[j],
                    derotations_.empty() ? nullptr : &derotations_[j]});
  label_stereo_flow_rows(disparity_, edges_, flows, gaps, *camera_, p.envelope, p.scene_flow,
                         danger_, ttc_, velocity_, rows,
                         startup_.residuals_m.empty() ? nullptr : &startup_.residuals_m);
}

Detector::Detector(const core::DetectorParams& params, const core::Camera& camera)
    : params_(params),
      camera_(camera),
      hysteresis_(params.signal),
      tracker_(params.signal, params.envelope.z_contact_m,
               camera.focal_px * camera.baseline_m / std::max(1, params.bm.num_disparities - 1),
               camera.focal_px * camera.baseline_m),
      severity_(params.signal) {
  if (!core::is_surveyed(params_.mode)) {
    const std::vector<int>& gaps =
        params_.mode == core::Mode::kStereoFlow ? params_.scene_flow.gaps : params_.stereo.gaps;
    if (!gaps.empty()) max_gap_ = std::max(1, *std::max_element(gaps.begin(), gaps.end()));
  } else if (params_.mode == core::Mode::kRelativeSize) {
    max_gap_ = params_.relative_size.gap_frames;
  }
}

LabelJob Detector::prepare(const core::StereoFrame& frame, FrameMaps maps) {
  const core::Needs need = core::needs(params_.mode);
  // Without a disparity the left image gives the size of the maps.
  const bool with_left = need.left_image || !need.disparity;
  if (with_left && (maps.left.empty() || maps.left.type() != CV_8UC1))
    throw core::InputError("detector: " + std::string(core::to_string(params_.mode)) +
                           " needs the left image, a non-empty CV_8U image");
  if (!need.disparity) {
    // A map of invalid disparities: the obstacles then have no distance.
    maps.disparity = cv::Mat(maps.left.size(), CV_32F, cv::Scalar(-1.0f));
  }
  const cv::Mat& disp = maps.disparity;
  if (disp.empty() || disp.type() != CV_32FC1)
    throw core::InputError("detector: the disparity map must be a non-empty CV_32F image");
  if (with_left && maps.left.size() != disp.size())
    throw core::InputError("detector: the left image and the disparity differ in size");
  if (!past_.empty() && past_.front().disparity.size() != disp.size())
    throw core::InputError("detector: the disparity map changed size within a stream");
  const bool flow_mode = params_.mode == core::Mode::kStereoFlow;
  if (need.flow && !maps.flow.empty() &&
      (maps.flow.type() != CV_32FC2 || maps.flow.size() != disp.size()))
    throw core::InputError("detector: the flow must be a CV_32FC2 map of the disparity's size");
  if (!past_.empty() && frame.index <= past_.front().index)
    throw core::InputError("detector: frames must arrive in increasing index order");

  LabelJob job;
  cv::Matx33d flow_derotation = cv::Matx33d::eye();  // of maps.flow (compensate_rotation)
  job.mode_ = params_.mode;
  job.flow_mode_ = flow_mode;
  job.params_ = &params_;
  job.camera_ = &camera_;
  job.disparity_ = disp;
  if (flow_mode) {
    if (maps.edges.empty()) depth_edges(params_, disp, maps.edges);
    job.edges_ = maps.edges;
    // The chain B_i, then each past frame's flow to the one before it, while unbroken.
    if (!maps.flow.empty()) {
      job.flows_.push_back(maps.flow);
      for (const Past& e : past_) {
        if (e.flow.empty()) break;
        job.flows_.push_back(e.flow);
      }
    }
    const int reach = std::min(static_cast<int>(job.flows_.size()), static_cast<int>(past_.size()));
    const bool derotate = params_.scene_flow.compensate_rotation && !maps.flow.empty();
    if (derotate) flow_derotation = derotation(estimate_ego_motion(maps.flow, disp, camera_));
    int reached = 0;
    for (int k : sampled_gaps(params_.scene_flow)) {
      // Usable once the chain reaches k camera frames back; then the oldest frame at most k
      // frames back (at least the previous one): without drops exactly frame i - k.
      if (reach == 0 || frame.index - past_[static_cast<size_t>(reach - 1)].index < k) continue;
      reached = k;
      int m = 0;
      for (int j = 1; j < reach; ++j)
        if (frame.index - past_[static_cast<size_t>(j)].index <= k) m = j;
      const Past& e = past_[static_cast<size_t>(m)];
      job.past_.push_back(e.disparity);
      job.past_edges_.push_back(e.edges);
      job.steps_.push_back(m + 1);
      job.spans_s_.push_back(frame.time_s - e.time_s);
      if (derotate) {
        // The rotations of the flows chained to past_[m], newest first.
        cv::Matx33d chain = flow_derotation;
        for (int j = 0; j < m; ++j) chain = chain * past_[static_cast<size_t>(j)].derotation;
        job.derotations_.push_back(chain);
      }
    }
    if (derotate && params_.scene_flow.predict_turn && !job.derotations_.empty()) {
      // The yaw of the longest gap's rotation: it turns camera i-k's coordinates into camera
      // i's, so a camera turning right by a turns points by -a.
      const cv::Matx33d& r = job.derotations_.back();
      job.yaw_rate_rps_ = -std::atan2(r(0, 2), r(2, 2)) / job.spans_s_.back();
    }
    allocate_stereo_flow_outputs(disp.size(), job.danger_, job.ttc_, job.velocity_);
    // Over the first frames of a chain (short of the longest gap) the disparity error dominates
    // the fit: its residuals at each sample time (now, and each past frame of the chain once;
    // after a dropped frame two gaps reach the same one) show how much (startup_doubt_se).
    const core::SceneFlowParams& sf = params_.scene_flow;
    if (sf.fit_velocity && sf.pool_surface_motion && sf.startup_doubt_se > 0 &&
        reached < max_gap_) {
      job.startup_.times_s = {0.0};
      for (size_t j = 0; j < job.spans_s_.size(); ++j)
        if (j == 0 || job.steps_[j] != job.steps_[j - 1])
          job.startup_.times_s.push_back(-job.spans_s_[j]);
      job.startup_.residuals_m.create(disp.size(),
                                      CV_32FC(static_cast<int>(job.startup_.times_s.size())));
    }
  } else if (core::is_surveyed(params_.mode)) {
    prepare_surveyed(frame, maps, job);
  } else {
    for (int k : params_.stereo.gaps)
      if (k <= static_cast<int>(past_.size())) {
        const Past& e = past_[static_cast<size_t>(k - 1)];
        job.past_.push_back(e.disparity);
        job.steps_.push_back(frame.index - e.index);
      }
  }

  // The maps are shared, not copied: nobody writes them after the workers are done.
  Past entry{frame.index,
             frame.time_s,
             disp,
             flow_mode ? maps.edges : cv::Mat(),
             params_.mode == core::Mode::kRelativeSize ? maps.left : cv::Mat(),
             flow_mode ? maps.flow : cv::Mat(),
             flow_derotation};
  past_.push_front(std::move(entry));
  while (static_cast<int>(past_.size()) > max_gap_) past_.pop_back();
  return job;
}

void Detector::prepare_surveyed(const core::StereoFrame& frame, const FrameMaps& maps,
                                LabelJob& job) const {
  job.left_ = maps.left;
  if (past_.empty()) return;
  const Past& previous = past_.front();
  switch (params_.mode) {
    case core::Mode::kMotionParallax:
    case core::Mode::kSceneFlowSeg:
      // The flow reaches the previous arrived frame (a dropped frame makes it a longer step).
      if (maps.flow.empty()) return;
      job.flows_.push_back(maps.flow);
      job.past_.push_back(previous.disparity);
      job.span_s_ = frame.time_s - previous.time_s;
      break;
    case core::Mode::kRelativeSize: {
      // The oldest arrived frame at most gap_frames back (at least the previous one).
      const Past* e = &previous;
      for (const Past& q : past_)
        if (frame.index - q.index <= params_.relative_size.gap_frames) e = &q;
      job.earlier_left_ = e->left;
      job.span_s_ = frame.time_s - e->time_s;
      break;
    }
    default:
      break;
  }
}

void LabelJob::conclude() {
  if (concluded_) return;
  const core::DetectorParams& p = *params_;
  const core::SceneFlowParams& sf = p.scene_flow;
  // The ground plane's pixels are never dangerous. With pooling, no surface joins the ground's
  // side with what stands on it. Without pooling only dangerous pixels are tested, so a frame
  // without any needs no plane (the same masks as testing every pixel).
  const bool pool = flow_mode_ && sf.pool_surface_motion;
  GroundPlane plane;
  bool fitted = false;
  auto ground_plane = [&]() -> const GroundPlane& {
    if (!fitted) plane = fit_ground_plane(disparity_, *camera_, sf.ground);
    fitted = true;
    return plane;
  };
  if (pool) {
    cv::Mat ground_side;
    if (sf.exclude_ground && sf.ground.split_surfaces)
      mark_ground_side(disparity_, *camera_, ground_plane(), sf.ground.tolerance_m,
                       sf.ground.side_margin_px, ground_side);
    // The velocities come from the longest gap that knows them: the noise gate uses its span.
    const double span_s =
        spans_s_.empty() ? 0.0 : *std::max_element(spans_s_.begin(), spans_s_.end());
    pool_surface_motion(disparity_, *camera_, p.envelope, sf, span_s, edges_, danger_, ttc_,
                        velocity_, startup_, yaw_rate_rps_, ground_side);
    startup_ = ChainResiduals{};  // a float a pixel per sample: not kept past the frame
  }
  if (flow_mode_ && sf.grow_into_edges)
    grow_danger_into_edges(disparity_, edges_, sf.edge_margin_px, sf.edge_step_px,
                           p.signal.open_size, danger_, ttc_, velocity_);
  if (flow_mode_ && sf.exclude_ground && cv::countNonZero(danger_) > 0) {
    cv::Mat ground;
    mark_ground(disparity_, *camera_, ground_plane(), sf.ground.tolerance_m, ground, danger_);
    danger_.setTo(0, ground);
    ttc_.setTo(std::numeric_limits<float>::quiet_NaN(), ground);
  }
  obstacles_ =
      extract_obstacles(danger_, disparity_, ttc_, *camera_, p.signal, velocity_, &obstacle_runs_);
  region_pixels_ = count_region_pixels(danger_, p.signal.region_columns);
  concluded_ = true;
}

core::Detection Detector::finish(const core::StereoFrame& frame, LabelJob& job) {
  core::Detection det;
  det.frame = frame.index;
  det.time_s = frame.time_s;
  job.conclude();
  det.danger = job.danger_;
  det.obstacles = std::move(job.obstacles_);
  tracker_.update(det.time_s, det.obstacles);
  // A blob whose track is not confirmed yet raises nothing: off the mask, out of the list.
  std::vector<bool> confirmed(det.obstacles.size(), true);
  bool any_unconfirmed = false;
  for (size_t i = 0; i < det.obstacles.size(); ++i) {
    const core::Obstacle& o = det.obstacles[i];
    confirmed[i] = o.predicted || o.seen_frames >= params_.signal.confirm_frames;
    any_unconfirmed = any_unconfirmed || !confirmed[i];
  }
  if (any_unconfirmed) {
    if (clear_obstacles(det.danger, job.obstacle_runs_, confirmed))
      job.region_pixels_ = count_region_pixels(det.danger, params_.signal.region_columns);
    std::vector<core::Obstacle> kept;
    for (size_t i = 0; i < det.obstacles.size(); ++i)
      if (confirmed[i]) kept.push_back(std::move(det.obstacles[i]));
    det.obstacles = std::move(kept);
  }
  // An obstacle kept by prediction after its blob vanished nearer than the matcher sees is
  // dangerous where it was last seen.
  bool painted = false;
  for (const core::Obstacle& o : det.obstacles)
    if (o.predicted && o.pixels == 0) {
      det.danger(o.bbox & cv::Rect(0, 0, det.danger.cols, det.danger.rows)).setTo(255);
      painted = true;
    }
  if (painted) job.region_pixels_ = count_region_pixels(det.danger, params_.signal.region_columns);
  det.regions = hysteresis_.update(job.region_pixels_);
  det.signal = std::any_of(det.regions.begin(), det.regions.end(),
                           [](const core::RegionSignal& r) { return r.fired; });
  det.severity =
      severity_.update(det.signal, severity_of(det.signal, det.obstacles, params_.signal));
  det.steering = steering_hint(det.regions);
  return det;
}

core::Detection Detector::process(const core::StereoFrame& frame, const FrameMaps& maps) {
  // The history shares the maps it keeps; a caller may reuse its buffers for the next frame.
  FrameMaps own{maps.disparity.clone(), maps.flow.clone(), maps.edges.clone(),
                maps.left.empty() ? frame.left : maps.left};
  LabelJob job = prepare(frame, std::move(own));
  job.run(cv::Range::all());
  return finish(frame, job);
}

}  // namespace sg::vision
