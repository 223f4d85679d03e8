#pragma once
/// The obstacle pipeline (DESIGN 1): emitter (read, stamp, pace, drop), a farm of W workers
/// (decode, stereo matching and, in Stereo-Flow mode, optical flow, each split into T row tiles),
/// a relay (in order: the detector's history), the labelling as farm tasks in row bands, the
/// collector (restore order, obstacles, signals), and its metrics. This layer wires the vision
/// kernels onto the par skeletons; it is the only place where both meet.
#include <atomic>
#include <cstddef>
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
  /// Pace the emitter like a camera at this rate, Hz; 0 = as fast as the pipeline accepts (a
  /// file: nothing is dropped). When paced, frame n is "captured" at n / pace_fps; a frame whose
  /// successor was captured before a token was free for it is dropped and counted.
  double pace_fps = 0.0;
  int workers = 1;  ///< W >= 1: farm tasks (SM, OF) running at once
  int tiles = 1;    ///< T >= 1: row tiles per task
  /// Frames in flight; 0 = automatic: W + 1, one frame ready beyond the workers (paced, it is
  /// held until its capture, so a run of costly frames delays it instead of losing it;
  /// docs/performance.md has the paced figures against W tokens).
  int tokens = 0;
  int threads = 0;  ///< task-arena size; 0 = all cores
  /// Split the optical-flow task into tiles too. Off by default: DIS works on an image pyramid,
  /// so tiled flow differs from whole-image flow near the cuts and detections could differ from
  /// the sequential reference; stereo matching tiles are bit-identical and always used.
  bool tile_flow = false;
  /// Hand each detection its disparity and flow maps (core::Detection::disparity, flow), e.g. to
  /// dump them. Off by default: they would keep two full-size maps alive per stored detection.
  bool keep_maps = false;
  /// Before the first frame, touch as much heap as the run will hold once its history of past
  /// maps is full (par::prefault_heap, sized from the camera's width and height, the longest gap
  /// and the tokens), so that the first frames do not fault their pages in. Worth it only where
  /// freed memory stays on the heap; `stereoguard run` and `eval` set it (with glibc tuned in
  /// main). Off by default.
  bool prefault_heap = false;
  /// A stop request, e.g. set from a signal handler or a user interface; null = none. Once it
  /// reads true, the emitter takes no more frames from the source; the frames in flight finish
  /// and are delivered to the sink in order, and run() returns normally with
  /// RunSummary::interrupted set. Checked before each frame is read; must outlive run().
  const std::atomic<bool>* stop = nullptr;
};

/// The W and T that `--workers auto` and `--tiles auto` (the CLI's defaults) pick for a task
/// arena of `threads` threads (0 = all the cores this process may use, par::default_threads()):
/// W = the threads, one farm task on each; T = 2 with more than one thread, so that a worker
/// whose frame's flow waits on the other core still splits its stereo matching (on 2 cores
/// `bench` measured W 2 T 2 the fastest of W 1-3 x T 1-4 in both detectors; docs/performance.md).
/// Every W and T give the same detections.
struct AutoConfiguration {
  int workers = 1;
  int tiles = 1;
};
AutoConfiguration auto_configuration(int threads = 0);

/// The heap a run of `options` holds at most for a camera of `width` x `height` px, roughly:
/// the history (disparity, and flow and depth edges in Stereo-Flow mode, for the longest gap)
/// and every frame in flight with its maps and labelling outputs. Bytes.
std::size_t heap_estimate(const RunOptions& options, int width, int height);

/// Every violation as text; empty when valid (includes core::validate of the detector params).
std::vector<std::string> validate(const RunOptions& options, const core::Camera& camera);

/// Tokens actually used by `options` (the automatic choice resolved).
int effective_tokens(const RunOptions& options);

/// The run's metrics (DESIGN 1, "Metrics").
struct RunSummary {
  int frames = 0;   ///< detections produced
  /// Frames lost: skipped by the paced emitter, or missing from the source's frame indices (a
  /// live camera's drops, DroppingSource).
  int dropped = 0;
  int alarm_frames = 0;
  std::optional<int> first_alarm_frame;
  std::optional<double> first_alarm_time_s;
  /// True when the run ended on RunOptions::stop before the source ended: `frames` counts the
  /// frames processed up to then.
  bool interrupted = false;
  int deadline_misses = 0;      ///< latency > 1 / pace_fps (paced runs only)
  double wall_s = 0.0;          ///< first frame read to last detection, s
  double throughput_fps = 0.0;  ///< frames / wall_s
  double service_ms = 0.0;      ///< mean interval between consecutive detections, ms
  double latency_p50_ms = 0.0, latency_p95_ms = 0.0, latency_p99_ms = 0.0, latency_max_ms = 0.0;
  double latency_mean_ms = 0.0;
  /// Busy time per stage summed over the run, ms (wall time inside the stage): emitter (read and
  /// stamp; decoding runs on the farm, a scenario renders here: core::PendingFrame::
  /// load_where_read), decode (imread, gray conversion: farm), stereo matching,
  /// optical flow, labelling (per-pixel danger, farm tasks after the relay), obstacles (mask
  /// cleaning, connected components, obstacle statistics: the last labelling task,
  /// LabelJob::conclude), collector (tracking, signals, sinks).
  double busy_emitter_ms = 0.0, busy_decode_ms = 0.0, busy_sm_ms = 0.0, busy_of_ms = 0.0,
         busy_label_ms = 0.0, busy_conclude_ms = 0.0, busy_collector_ms = 0.0;
  double collector_max_ms = 0.0;  ///< the collector's longest frame, ms
  /// The collector's thread CPU time, summed over the run and its longest frame, ms: on a loaded
  /// machine wall busy times include waits for a core; these do not.
  double busy_collector_cpu_ms = 0.0, collector_cpu_max_ms = 0.0;
  /// The configuration that ran.
  std::string mode;
  int workers = 1, tiles = 1, tokens = 1, threads = 0;
  bool tile_flow = false;
  double pace_fps = 0.0;

  nlohmann::json to_json() const;
  /// A few human lines: frames, alarms, first alarm, fps, latency, drops.
  std::string text() const;
};

/// Called for every detection, in frame order, with its frame (from the collector's thread).
using DetectionSink = std::function<void(const core::StereoFrame&, const core::Detection&)>;

/// Runs the detector over the whole source. Throws core::InputError for invalid options or broken
/// input; an exception anywhere stops the run and is rethrown here; detections already delivered
/// to `sink` stay delivered. Every (W, T, tokens) gives the same detections as W = T = 1.
RunSummary run(core::FrameSource& source, const RunOptions& options, const DetectionSink& sink);

}  // namespace sg::pipeline
