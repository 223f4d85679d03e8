#pragma once
/// The collector's labelling step around pure functions: owns the past disparity maps and the
/// hysteresis state; one Detection per frame, in frame order.
///
/// A frame passes four steps, which a pipeline may run on different threads:
///   prepare (serial, in frame order: checks, history)  -> LabelJob
///   LabelJob::run on row ranges (any threads, tiles)   -> per-pixel danger, TTC, velocity
///   LabelJob::conclude (any thread, once all rows ran)  -> cleaned mask, obstacles, region counts
///   finish  (serial, in frame order: tracking, signals) -> Detection
/// process() runs them in a row. prepare and finish touch disjoint state, so the prepare of
/// frame i + 1 may run while frame i's labelling or finish is still running; conclude touches
/// only its job, so the jobs of several frames may conclude at once.
#include <deque>
#include <opencv2/core.hpp>
#include <vector>

#include "sg/core/camera.hpp"
#include "sg/core/detection.hpp"
#include "sg/core/frame.hpp"
#include "sg/core/params.hpp"
#include "sg/vision/scene_flow.hpp"
#include "sg/vision/segment_motion.hpp"
#include "sg/vision/signals.hpp"
#include "sg/vision/tracking.hpp"

namespace sg::vision {

/// What the workers computed for one frame.
struct FrameMaps {
  /// CV_32F, px, invalid < 0; empty for the detectors that do not need it (core::needs).
  cv::Mat disparity{};
  /// CV_32FC2 backward flow B_i from L_i to the left image of the previous frame that reached the
  /// detector (Stereo-Flow mode), empty for the first frame and in Stereo mode.
  cv::Mat flow{};
  /// Optional CV_8U depth-edge mask of `disparity` (depth_edges()); computed by prepare() when
  /// empty in Stereo-Flow mode. A worker may compute it right after the disparity.
  cv::Mat edges{};
  /// The frame's left image (CV_8U), a share: relative-size and sceneflow-seg read it (and the
  /// earlier frames' from the history). Detector::process takes the frame's when empty.
  cv::Mat left{};
};

/// The depth-edge mask the Stereo-Flow labelling uses for `disparity` (mark_depth_edges with the
/// scene_flow edge settings, thin structures given back with keep_thin_structures,
/// vision/edge_margin.hpp); CV_8U.
void depth_edges(const core::DetectorParams& params, const cv::Mat& disparity, cv::Mat& edges);

/// The per-pixel labelling of one frame, made by Detector::prepare: read-only shares of the maps
/// it reads and its own outputs. run() may be called at once from several threads on disjoint
/// row ranges; every row must be run once before Detector::finish.
class LabelJob {
 public:
  /// Labels rows `rows` (cv::Range::all(): every row).
  void run(cv::Range rows);
  /// The per-frame work of finish that needs the whole mask but no state kept between frames:
  /// in Stereo-Flow mode growing the blobs into the depth-edge margin (scene_flow.grow_into_edges)
  /// and clearing the ground (scene_flow.exclude_ground), then cleaning the mask and finding the
  /// obstacles (extract_obstacles) and the dangerous pixels per region. Call once, after every
  /// row was run; Detector::finish calls it when nobody did.
  void conclude();
  /// True when run() accepts row ranges (Stereo-Flow mode); otherwise call run(all) once.
  bool tileable() const { return flow_mode_; }
  /// Image rows.
  int rows() const { return disparity_.rows; }

 private:
  friend class Detector;
  /// The surveyed detectors' labelling (vision/surveyed.hpp), over the whole image.
  void run_surveyed();

  core::Mode mode_ = core::Mode::kStereo;
  bool flow_mode_ = false;
  const core::DetectorParams* params_ = nullptr;
  const core::Camera* camera_ = nullptr;
  cv::Mat disparity_, edges_;
  std::vector<cv::Mat> flows_;       ///< Stereo-Flow chain, newest first
  std::vector<cv::Mat> past_;        ///< past disparities the gaps compare with
  std::vector<cv::Mat> past_edges_;  ///< their depth edges (Stereo-Flow)
  std::vector<int> steps_;           ///< Stereo-Flow: flows chained to past_[j]; Stereo: gap frames
  std::vector<double> spans_s_;      ///< Stereo-Flow: time from past_[j] to now, s
  /// Stereo-Flow with scene_flow.compensate_rotation: turns past_[j]'s camera coordinates into
  /// the current orientation; empty = no compensation.
  std::vector<cv::Matx33d> derotations_;
  /// Stereo-Flow with scene_flow.predict_turn: the platform's yaw rate over the longest gap,
  /// rad/s (+ = turning right); 0 = the envelope test looks straight ahead.
  double yaw_rate_rps_ = 0.0;
  cv::Mat danger_, ttc_, velocity_;
  // The surveyed detectors: the left images compared (relative-size: the earlier one of the
  // gap; sceneflow-seg: the current one), and the time between the frames compared, s; 0 when
  // the history holds nothing to compare with (nothing is dangerous then).
  cv::Mat left_, earlier_left_;
  double span_s_ = 0.0;
  /// Stereo-Flow with the velocity fit while the chain does not reach the longest gap yet (the
  /// start of a stream): the fit's residuals, by which pooling doubts each surface's velocity
  /// (scene_flow.startup_doubt_se); empty otherwise.
  ChainResiduals startup_;
  bool concluded_ = false;
  std::vector<core::Obstacle> obstacles_;  ///< conclude(): untracked obstacles
  std::vector<ObstacleRun> obstacle_runs_; ///< conclude(): their pixels in danger_
  std::vector<int> region_pixels_;         ///< conclude(): dangerous pixels per region
};

class Detector {
 public:
  /// params must be valid (core::validate).
  Detector(const core::DetectorParams& params, const core::Camera& camera);

  /// Checks the maps, records them in the history and returns the labelling of this frame against
  /// the history before it. Frames must arrive in increasing index order; indices count camera
  /// frames, so a gap in them is a dropped frame. Stereo mode: gap k compares D_i with the map of
  /// frame i - k when it was kept (label_stereo). Stereo-Flow mode: the history is the chain of
  /// frames that arrived, each with its flow to the one before it; gap k compares with the oldest
  /// arrived frame at most k camera frames back (at least the previous arrived one), following
  /// the flows between them, over the real time between their time_s stamps
  /// (label_stereo_flow_rows). A dropped frame thus shortens the chains instead of restarting
  /// them; an empty maps.flow cuts the chain there. With scene_flow.compensate_rotation the
  /// camera's rotation is estimated from each flow (estimate_ego_motion) and removed over every
  /// gap. The surveyed detectors (vision/surveyed.hpp) compare with the previous arrived frame
  /// (motion-parallax: its flow; sceneflow-seg: its disparity and the flow), relative-size with
  /// the oldest arrived frame at most relative_size.gap_frames back (its left image). Throws
  /// core::InputError when the detector needs a disparity and it is not a non-empty CV_32F map,
  /// when relative-size or a detector without disparity gets no CV_8U left image, when a non-empty flow is not CV_32FC2 of its size, when the size
  /// changes within the stream, or when frames come out of order.
  LabelJob prepare(const core::StereoFrame& frame, FrameMaps maps);

  /// Turns a labelled frame into its Detection: LabelJob::conclude unless it ran (in Stereo-Flow
  /// mode with scene_flow.grow_into_edges the dangerous blobs grow back over the depth-edge margin
  /// (grow_danger_into_edges); with scene_flow.exclude_ground, dangerous pixels on or below a
  /// ground plane fitted to D_i are cleared; the obstacles, with the mean 3D velocity in
  /// Stereo-Flow mode, are extracted); then the obstacles are tracked over frames
  /// with their TTC from a fit (ObstacleTracker), region counts, hysteresis, severity (held by
  /// SeverityHold) and steering. Fills frame and time_s from `frame`, danger = the cleaned
  /// mask; leaves latency_ms to the caller. Jobs must come in the order of prepare.
  core::Detection finish(const core::StereoFrame& frame, LabelJob& job);

  /// prepare, run over every row, finish.
  core::Detection process(const core::StereoFrame& frame, const FrameMaps& maps);

 private:
  /// One frame of the history.
  struct Past {
    int index = 0;
    double time_s = 0.0;
    cv::Mat disparity;
    cv::Mat edges;  ///< Stereo-Flow
    cv::Mat left;   ///< relative-size
    cv::Mat flow;   ///< Stereo-Flow: its flow to the next older entry; empty = chain cut
    /// With compensate_rotation: turns the next older entry's camera coordinates into this
    /// entry's orientation (from `flow`, estimate_ego_motion).
    cv::Matx33d derotation = cv::Matx33d::eye();
  };

  /// prepare's part for the surveyed detectors: what the frame is compared with.
  void prepare_surveyed(const core::StereoFrame& frame, const FrameMaps& maps,
                        LabelJob& job) const;

  core::DetectorParams params_;
  core::Camera camera_;
  int max_gap_ = 1;              ///< longest gap of the active mode, camera frames
  std::deque<Past> past_;        ///< newest first (prepare only)
  RegionHysteresis hysteresis_;  ///< finish only (as the two below)
  ObstacleTracker tracker_;
  SeverityHold severity_;
};

}  // namespace sg::vision
