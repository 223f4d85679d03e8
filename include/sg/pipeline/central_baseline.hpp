#pragma once
/// The baseline beside every real-recording figure (DESIGN 4.1, docs/real-recordings.md): the
/// central-quarter median distance alarm a student writes first. Per frame StereoSGBM and the
/// median disparity of the central quarter (vision/central_median.hpp) give a distance; its
/// closing speed is the least-squares slope over the trailing window; the alarm is the
/// envelope's TTC rule on that distance. One frame at a time, no threads of its own.
#include <deque>
#include <utility>

#include "sg/core/camera.hpp"
#include "sg/core/detection.hpp"
#include "sg/core/frame.hpp"
#include "sg/core/params.hpp"
#include "sg/core/source.hpp"
#include "sg/pipeline/runner.hpp"

namespace sg::pipeline {

struct CentralBaselineOptions {
  /// The detector's parameters: bm.num_disparities and bm.block_size set the matcher,
  /// envelope.z_contact_m and envelope.horizon_s the alarm, signal.ttc_danger_s the severity.
  core::DetectorParams params;
  double window_s = 0.5;          ///< trailing fit window: frames with t >= now - window_s, s
  int min_frames = 3;             ///< known distances the fit needs in the window
  double min_closing_mps = 0.05;  ///< slower is not an approach, m/s
  bool keep_maps = false;         ///< hand each detection its disparity map (for --dump)
};

/// The baseline's temporal state (the trailing distances) around the pure per-frame functions.
class CentralBaseline {
 public:
  CentralBaseline(CentralBaselineOptions options, const core::Camera& camera);

  /// Frames in stream order. The detection has signal (alarm), severity (danger when the TTC is
  /// <= signal.ttc_danger_s or the distance <= z_contact), one region "centre" and, when the
  /// central median is known, one obstacle: the central box, its valid pixels, the distance, the
  /// closing speed and TTC when the fit has them. latency_ms = processing time of the frame.
  core::Detection process(const core::StereoFrame& frame);

 private:
  CentralBaselineOptions options_;
  core::Camera camera_;
  std::deque<std::pair<double, double>> history_;  ///< (t_s, distance_m) of the trailing window
};

/// Runs the baseline over the whole source, calling `sink` (may be empty) for each detection in
/// frame order. Throws core::InputError for invalid parameters (core::validate against the
/// source's camera, as the detector's run does) or broken input. The summary has frames, alarm
/// frames, the first alarm, wall time, throughput and latencies; mode "central-median".
RunSummary run_central_baseline(core::FrameSource& source, const CentralBaselineOptions& options,
                                const DetectionSink& sink);

}  // namespace sg::pipeline
