#pragma once
/// Throughput and latency sweeps (the `bench` command): modes x W x T at chosen resolutions, on
/// frames rendered once and held in memory, beside the baseline a user would write (a plain
/// sequential OpenCV loop) measured in the same run.
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sg/core/params.hpp"
#include "sg/core/source.hpp"

namespace sg::pipeline {

struct BenchConfig {
  std::vector<core::Mode> modes = {core::Mode::kStereo, core::Mode::kStereoFlow};
  std::vector<int> workers = {1, 2, 3};
  std::vector<int> tiles = {1, 2, 4};
  std::vector<cv::Size> resolutions = {{640, 480}, {1242, 375}};
  int frames = 300;          ///< frames per configuration
  int num_disparities = 64;  ///< stereo search range, px
  /// Matcher of the pipeline rows (the baseline loops stay StereoBM, the reference).
  core::Matcher matcher = core::Matcher::kFast;
  core::MatchCost cost = core::MatchCost::kSad;  ///< fast matcher's cost
  int threads = 0;           ///< task-arena size (0 = all cores)
  int tokens = 0;            ///< frames in flight of the pipeline rows (0 = automatic: RunOptions)
  std::string scenario = "head-on";
  /// Also run the best configuration of each mode (first resolution, best_for_pacing) paced at
  /// these fractions of its measured capacity (empty = none).
  std::vector<double> pace_fractions = {0.8, 1.5};
  /// The capacity those fractions refer to: the median throughput of this many runs of the best
  /// configuration (its sweep row and capacity_runs - 1 more, rows of kind "capacity"), 1..9. One
  /// run of 150 frames on a busy 2-core machine reads up to 20 % off (head-on, W 2 T 2: 97-112
  /// fps in six sweeps), and a pace set from a run that read high is no longer 80 % of capacity.
  /// With more than one, one more unpaced run follows the paced rows (kind "recheck"): whether
  /// the machine kept its speed while they ran.
  int capacity_runs = 3;
  /// When set, the frames come from this input instead of the scenario: read once into memory (up
  /// to `frames`, played forwards then backwards when shorter), at the input's own resolution and
  /// camera; `scenario` and `resolutions` are then ignored.
  std::function<std::unique_ptr<core::FrameSource>()> open_input;
};

std::vector<std::string> validate(const BenchConfig& config);

struct BenchRow {
  /// "baseline" (plain loop, OpenCV on one thread: the reference), "opencv-mt" (the same loop
  /// with OpenCV's own parallel loops), "pipeline", "capacity" (more runs of the best pipeline
  /// row), "paced" or "recheck" (the best row once more, after the paced rows)
  std::string kind;
  std::string mode;        ///< "stereo" / "stereo-flow"
  cv::Size resolution;
  int workers = 0, tiles = 0, tokens = 0;
  double pace_fps = 0.0;   ///< paced runs: the camera rate, Hz
  int frames = 0, dropped = 0, deadline_misses = 0;
  double fps = 0.0;        ///< throughput, frames / s
  double speedup = 0.0;     ///< fps / opencv-mt fps of the same mode and resolution
  double speedup_1t = 0.0;  ///< fps / baseline (one-thread loop) fps, same mode and resolution
  double latency_p50_ms = 0.0, latency_p99_ms = 0.0, service_ms = 0.0;
  /// Per-frame signals equal to the baseline's (pipeline rows) / to the unpaced run's (paced rows:
  /// only comparable when nothing was dropped).
  bool same_detections = true;
  /// Paced and recheck rows: the capacity the pace is a fraction of (the median fps of the
  /// capacity runs of this configuration), the number of those runs, and their spread, (max -
  /// min) / median: a large spread means the machine's speed changed between runs, so the pace
  /// may not be the fraction of the capacity that was asked for. Not in the CSV.
  double capacity_fps = 0.0, capacity_spread = 0.0;
  int capacity_runs = 0;
};

/// "kind,mode,width,height,workers,tiles,tokens,pace_fps,frames,dropped,deadline_misses,fps,
/// speedup,latency_p50_ms,latency_p99_ms,service_ms,same_detections,speedup_1t"
std::string bench_csv_header();
/// "yes" / "no", or "n/a" for a paced run that dropped frames.
std::string same_detections_text(const BenchRow& row);
std::string to_csv(const BenchRow& row);

/// The configuration a user would pace a camera with, among `pipeline` rows: the lowest p99
/// latency among those within 5 % of the highest throughput (run-to-run noise), so that more
/// workers than cores, which add latency but no throughput, are not chosen by chance. Returns
/// the row's index, or rows.size() when there is none.
std::size_t best_for_pacing(const std::vector<BenchRow>& rows);

/// Runs the sweep; `on_row` sees each row as soon as it is measured.
std::vector<BenchRow> run_bench(const BenchConfig& config,
                                const std::function<void(const BenchRow&)>& on_row);

}  // namespace sg::pipeline
