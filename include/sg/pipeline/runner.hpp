#pragma once
/// The obstacle pipeline: emitter (read, stamp, pace), workers (stereo matching, flow), collector
/// (labelling, signals), and its metrics. This layer wires the vision kernels onto the skeletons.
#include <chrono>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "sg/core/detection.hpp"
#include "sg/core/frame.hpp"
#include "sg/core/params.hpp"
#include "sg/core/source.hpp"

namespace sg::pipeline {

struct RunOptions {
  core::DetectorParams params;
  /// Pace the emitter like a camera at this rate, Hz; 0 = as fast as the pipeline accepts.
  double pace_fps = 0.0;
};

/// Every violation as text; empty when valid (includes core::validate of the detector params).
std::vector<std::string> validate(const RunOptions& options, const core::Camera& camera);

/// Latency percentiles and throughput of a run (DESIGN 1, "Metrics").
struct RunSummary {
  int frames = 0;
  int alarm_frames = 0;
  std::optional<int> first_alarm_frame;
  std::optional<double> first_alarm_time_s;
  double wall_s = 0.0;          ///< first frame read to last detection, s
  double throughput_fps = 0.0;  ///< frames / wall_s
  double latency_p50_ms = 0.0, latency_p95_ms = 0.0, latency_p99_ms = 0.0, latency_max_ms = 0.0;
  double service_ms = 0.0;      ///< mean interval between consecutive detections, ms

  nlohmann::json to_json() const;
  /// A few human lines: frames, alarms, first alarm, fps, latency.
  std::string text() const;
};

/// Called for every detection, in frame order, with its frame.
using DetectionSink = std::function<void(const core::StereoFrame&, const core::Detection&)>;

/// Runs the detector over the whole source (sequentially: W = 1, T = 1). Throws core::InputError
/// for invalid options or broken input; detections already delivered to `sink` stay delivered.
RunSummary run(core::FrameSource& source, const RunOptions& options, const DetectionSink& sink);

}  // namespace sg::pipeline
