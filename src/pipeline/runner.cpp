#include "sg/pipeline/runner.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <iomanip>
#include <memory>
#include <mutex>
#include <numeric>
#include <sstream>

#include "sg/core/error.hpp"
#include "sg/par/backend.hpp"
#include "sg/par/farm.hpp"
#include "sg/par/memory.hpp"
#include "sg/par/metrics.hpp"
#include "sg/par/tiles.hpp"
#include "sg/vision/detector.hpp"
#include "sg/vision/frame_kernels.hpp"

namespace sg::pipeline {
namespace {

/// A frame read and stamped by the emitter, decoded by whichever farm task needs it first (the
/// frame's own tasks, or the flow task of the next frame, which needs this left image): once,
/// off the emitter. A failed decode throws to every caller.
class LazyFrame {
 public:
  explicit LazyFrame(core::PendingFrame pending) : pending_(std::move(pending)) {
    header_.index = pending_.index;
    header_.time_s = pending_.time_s;
  }
  /// The decoded, checked frame; decodes on the first call (thread-safe).
  const core::StereoFrame& get() {
    std::call_once(once_, [this] {
      const par::Stopwatch watch;
      core::StereoFrame frame = pending_.load();
      frame.index = pending_.index;
      frame.time_s = pending_.time_s;
      vision::check_frame(frame);
      frame_ = std::move(frame);
      pending_.load = nullptr;  // frees what the load captured
      decode_ms_ = watch.elapsed_ms();
    });
    return frame_;
  }
  /// Index and time only, known without decoding.
  const core::StereoFrame& header() const { return header_; }
  /// core::PendingFrame::load_where_read.
  bool load_where_read() const { return pending_.load_where_read; }  // get() clears only load
  /// Time the decode took, ms (0 before it ran).
  double decode_ms() const { return decode_ms_; }

 private:
  std::once_flag once_;
  core::PendingFrame pending_;
  core::StereoFrame header_, frame_;
  double decode_ms_ = 0.0;
};

/// One frame travelling through the farm.
struct FrameJob {
  std::shared_ptr<LazyFrame> frame;
  std::shared_ptr<LazyFrame> previous;  ///< the frame emitted before, for the flow; null at first
  vision::FrameMaps maps;
  vision::LabelJob label;
  cv::Mat kept_disparity, kept_flow;  ///< shares of the maps for the sink (RunOptions::keep_maps)
  par::TimePoint acquired;
  double sm_ms = 0.0, of_ms = 0.0;
  std::vector<double> label_ms;  ///< one per labelling tile
  /// Labelling bands not yet finished; the last one concludes the job (LabelJob::conclude).
  std::unique_ptr<std::atomic<int>> bands_left;
  double conclude_ms = 0.0;
};

/// The emitter: reads frames (decoding is left to the farm), paces them like a camera and drops
/// what a camera would overwrite, without decoding it. A paced frame is "acquired" at its capture
/// time, so its latency includes any wait for a token.
class Emitter {
 public:
  Emitter(core::FrameSource& source, double pace_fps, const std::atomic<bool>* stop)
      : source_(source), pace_fps_(pace_fps), stop_(stop) {}

  std::optional<FrameJob> operator()() {
    if (stop_ && stop_->load(std::memory_order_relaxed)) {
      stopped_ = true;
      return std::nullopt;
    }
    const par::TimePoint begin = par::now();
    const int lost_before = dropped();
    std::optional<core::PendingFrame> frame = read();
    if (!frame) return std::nullopt;
    if (pace_fps_ > 0) {
      // A camera overwrites a frame nobody took before the next one arrived: while the successor
      // of this frame has been captured already, this frame is lost (dropped) and the successor
      // takes its place. The last frame of a stream has no successor and is never dropped.
      while (capture_time(emitted_ + dropped_ + 1) <= par::now()) {
        std::optional<core::PendingFrame> successor = read();
        if (!successor) break;
        ++dropped_;
        frame = std::move(successor);
      }
    }
    frames_since_loss_ = dropped() > lost_before ? 0 : frames_since_loss_ + 1;
    behind_.store(frames_since_loss_ < kBehindFrames, std::memory_order_relaxed);
    FrameJob job;
    job.frame = std::make_shared<LazyFrame>(std::move(*frame));
    job.previous = previous_;
    previous_ = job.frame;
    if (job.frame->load_where_read()) job.frame->get();  // the emitter's work, not the farm's
    busy_ms_ += par::elapsed_ms(begin);
    // A paced frame taken before its capture time waits for it in the farm
    // (FarmConfig::not_before), which holds it off the workers.
    job.acquired = pace_fps_ > 0 ? capture_time(emitted_ + dropped_) : par::now();
    acquired_ = job.acquired;
    ++emitted_;
    return job;
  }

  /// When the frame emitted last was (or will be) captured.
  par::TimePoint acquired() const { return acquired_; }

  /// Frames lost: dropped here, or missing from the source's indices (a live camera's drops).
  int dropped() const { return dropped_ + lost_; }
  /// True while the camera may outpace the pipeline: a frame was lost within the last
  /// kBehindFrames frames taken, or fewer than that were taken since the start (nothing shows yet
  /// that the pipeline keeps up). Read from the farm's threads (FarmConfig::admit_just_in_time).
  bool falling_behind() const { return behind_.load(std::memory_order_relaxed); }
  double busy_ms() const { return busy_ms_; }
  /// True when the stream ended on the stop request rather than at the source's end.
  bool stopped() const { return stopped_; }
  void start(par::TimePoint t0) { t0_ = t0; }

 private:
  std::optional<core::PendingFrame> read() {
    std::optional<core::PendingFrame> frame = source_.next_pending();
    if (frame) {
      if (last_index_ >= 0) lost_ += std::max(0, frame->index - last_index_ - 1);
      last_index_ = frame->index;
    }
    return frame;
  }

  /// When the paced camera captures its n-th frame.
  par::TimePoint capture_time(int n) const {
    return t0_ + std::chrono::duration_cast<par::Clock::duration>(
                     std::chrono::duration<double>(n / pace_fps_));
  }

  core::FrameSource& source_;
  double pace_fps_;
  const std::atomic<bool>* stop_;
  bool stopped_ = false;
  par::TimePoint t0_;
  std::shared_ptr<LazyFrame> previous_;
  par::TimePoint acquired_;
  /// Under steady overload a frame is lost at every other frame taken or so; a single slow frame
  /// makes the pipeline fall behind for a few frames only.
  static constexpr int kBehindFrames = 4;
  int emitted_ = 0, dropped_ = 0;
  /// From 0, so that the first frames are taken just in time too: with W + 1 tokens a camera
  /// that outpaces the pipeline otherwise fills every token before its first loss (bench at 150 %
  /// of capacity: median p99 2.39 instead of 2.59 service times; docs/performance.md).
  int frames_since_loss_ = 0;
  std::atomic<bool> behind_{false};
  int lost_ = 0, last_index_ = -1;
  double busy_ms_ = 0.0;
};

/// Runs `kernel(rows)` over T row tiles of `rows_total` rows.
template <class Kernel>
void tiled(int rows_total, int tiles, Kernel&& kernel) {
  if (tiles <= 1) {
    kernel(cv::Range::all());
    return;
  }
  par::parallel_for_tiles(rows_total, tiles,
                          [&](int, int begin, int end) { kernel(cv::Range(begin, end)); });
}

/// The farm's first tasks for one frame, what the detector needs (core::needs): SM, which decodes
/// the frame (or a decode alone for a detector without disparity), and OF from the second frame
/// on (it needs this frame's and the previous frame's left image).
par::TaskList make_tasks(FrameJob& job, const RunOptions& o) {
  const core::Needs need = core::needs(o.params.mode);
  const bool flow_mode = o.params.mode == core::Mode::kStereoFlow;
  const bool with_flow = need.flow && job.previous;
  par::TaskList tasks;
  tasks.emplace_back([&job, &o, flow_mode, need] {
    const core::StereoFrame& frame = job.frame->get();
    if (!need.disparity) return;
    const par::Stopwatch watch;
    vision::allocate_maps(frame.left.size(), false, job.maps.disparity, job.maps.flow);
    tiled(frame.left.rows, o.tiles, [&](cv::Range rows) {
      vision::disparity_rows(frame, o.params, job.maps.disparity, rows);
    });
    vision::disparity_finish(frame, o.params, job.maps.disparity);
    if (flow_mode) vision::depth_edges(o.params, job.maps.disparity, job.maps.edges);
    job.sm_ms = watch.elapsed_ms();
  });
  if (with_flow) {
    tasks.emplace_back([&job, &o] {
      const cv::Mat& current = job.frame->get().left;
      const cv::Mat& previous = job.previous->get().left;
      const par::Stopwatch watch;
      job.maps.flow.create(current.size(), CV_32FC2);
      tiled(current.rows, o.tile_flow ? o.tiles : 1, [&](cv::Range rows) {
        vision::flow_rows(current, previous, o.params, job.maps.flow, rows);
      });
      job.of_ms = watch.elapsed_ms();
    });
  }
  return tasks;
}

/// The relay (serial, in frame order): the detector records the frame's maps in its history and
/// hands back the frame's labelling, which the farm runs in row bands (max(W, T) of them); the
/// band that finishes last concludes it (mask cleaning, connected components, obstacle
/// statistics), so that the collector keeps only what needs the stream order.
par::TaskList relay_tasks(FrameJob& job, vision::Detector& detector, const RunOptions& o) {
  // The previous frame is decoded (its own first task did it) and no longer needed here.
  job.previous.reset();
  if (o.keep_maps) {
    job.kept_disparity = job.maps.disparity;
    job.kept_flow = job.maps.flow;
  }
  job.maps.left = job.frame->get().left;
  job.label = detector.prepare(job.frame->header(), std::move(job.maps));
  const int bands =
      job.label.tileable() ? par::tile_count(job.label.rows(), std::max(o.workers, o.tiles)) : 1;
  job.label_ms.assign(static_cast<size_t>(bands), 0.0);
  job.bands_left = std::make_unique<std::atomic<int>>(bands);
  par::TaskList tasks;
  for (int b = 0; b < bands; ++b) {
    tasks.emplace_back([&job, b, bands] {
      par::Stopwatch watch;
      if (bands == 1) {
        job.label.run(cv::Range::all());
      } else {
        const par::RowRange r = par::tile_rows(job.label.rows(), bands, b);
        job.label.run(cv::Range(r.begin, r.end));
      }
      job.label_ms[static_cast<size_t>(b)] = watch.elapsed_ms();
      // acq_rel: the last band sees every other band's rows.
      if (job.bands_left->fetch_sub(1, std::memory_order_acq_rel) != 1) return;
      watch.restart();
      job.label.conclude();
      job.conclude_ms = watch.elapsed_ms();
    });
  }
  return tasks;
}

std::string format_ms(double v) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(1) << v;
  return s.str();
}

}  // namespace

AutoConfiguration auto_configuration(int threads) {
  const int cores = threads > 0 ? threads : par::default_threads();
  return {std::max(1, cores), cores > 1 ? 2 : 1};
}

int effective_tokens(const RunOptions& o) {
  if (o.tokens > 0) return o.tokens;
  // One frame ready beyond the workers. A file's waits for a worker. A paced camera's is taken
  // as soon as a token frees and held until its capture (FarmConfig::not_before), so it starts
  // when a worker frees rather than when the frame two before it is done; with W tokens a run
  // of costly frames made each frame wait after its capture until one was lost
  // (docs/performance.md). Once the camera outpaces the pipeline, frames are taken just in time
  // instead (FarmConfig::admit_just_in_time), so the extra token does not make them wait.
  return o.workers + 1;
}

std::size_t heap_estimate(const RunOptions& o, int width, int height) {
  if (width <= 0 || height <= 0) return 0;
  const bool flow = core::needs(o.params.mode).flow;
  const std::vector<int>& gaps = flow ? o.params.scene_flow.gaps : o.params.stereo.gaps;
  const int history = gaps.empty() ? 1 : *std::max_element(gaps.begin(), gaps.end());
  // Kept per past frame: disparity (4 B/px), and flow (8) and depth edges (1) for Stereo-Flow.
  const std::size_t kept = flow ? 13 : 4;
  // In flight per frame: two gray images, disparity, flow, depth edges, danger, TTC, velocity,
  // and the labelling's surface labels and candidates: about 48 B/px.
  const std::size_t in_flight = 48;
  const auto pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  return pixels * (kept * static_cast<std::size_t>(history) +
                   in_flight * static_cast<std::size_t>(effective_tokens(o) + 1));
}

std::vector<std::string> validate(const RunOptions& o, const core::Camera& camera) {
  std::vector<std::string> out = core::validate(o.params, camera);
  auto require = [&out](bool ok, const std::string& what) {
    if (!ok) out.push_back(what);
  };
  require(std::isfinite(o.pace_fps) && o.pace_fps >= 0,
          "fps=" + format_ms(o.pace_fps) + ": must be >= 0 (0 = as fast as possible)");
  require(o.workers >= 1 && o.workers <= 64,
          "workers=" + std::to_string(o.workers) + ": must be in 1..64");
  require(o.tiles >= 1 && o.tiles <= 64, "tiles=" + std::to_string(o.tiles) + ": must be in 1..64");
  require(o.tiles <= camera.height / 8 || o.tiles == 1,
          "tiles=" + std::to_string(o.tiles) + ": at most image height / 8 (" +
              std::to_string(camera.height / 8) + ")");
  require(o.tokens >= 0 && o.tokens <= 256,
          "tokens=" + std::to_string(o.tokens) + ": must be in 0..256 (0 = automatic)");
  require(o.threads >= 0 && o.threads <= 256,
          "threads=" + std::to_string(o.threads) + ": must be in 0..256 (0 = all cores)");
  return out;
}

RunSummary run(core::FrameSource& source, const RunOptions& options, const DetectionSink& sink) {
  core::throw_if_invalid(validate(options, source.camera()), "invalid parameters");
  vision::Detector detector(options.params, source.camera());

  RunSummary s;
  s.mode = core::to_string(options.params.mode);
  s.workers = options.workers;
  s.tiles = options.tiles;
  s.tokens = effective_tokens(options);
  s.threads = options.threads;
  s.tile_flow = options.tile_flow;
  s.pace_fps = options.pace_fps;

  par::FarmConfig farm;
  farm.backend =
      options.workers == 1 && options.tiles == 1 ? par::Backend::kSequential : par::Backend::kTbb;
  farm.workers = options.workers;
  farm.tokens = s.tokens;
  farm.threads = options.threads;

  if (options.prefault_heap) {
    par::prefault_heap(heap_estimate(options, source.camera().width, source.camera().height));
  }
  Emitter emitter(source, options.pace_fps, options.stop);
  // A camera that outpaces the pipeline: the next frame is taken when it can start at once, so it
  // is the freshest (its latency counts from its capture), not as soon as a token frees, when it
  // would wait behind the older frames' stereo and flow. At 150 % of capacity: a median latency
  // of 1.7-1.8 service times instead of 2.2-2.3, at up to about 8 % fewer frames processed
  // (docs/performance.md). A file read as fast as possible has no capture time to age from.
  if (options.pace_fps > 0 || source.live())
    farm.admit_just_in_time = [&emitter] { return emitter.falling_behind(); };
  if (options.pace_fps > 0) farm.not_before = [&emitter] { return emitter.acquired(); };
  par::LatencyStats latency;
  const par::TimePoint start = par::now();
  emitter.start(start);
  par::TimePoint last_done = start;
  double service_sum_ms = 0.0;
  const double deadline_ms = options.pace_fps > 0 ? 1000.0 / options.pace_fps : 0.0;

  auto collect = [&](FrameJob&& job) {
    const par::Stopwatch watch;
    const par::CpuStopwatch cpu_watch;
    const core::StereoFrame& frame = job.frame->get();
    core::Detection detection = detector.finish(frame, job.label);
    if (options.keep_maps) {
      detection.disparity = job.kept_disparity;
      detection.flow = job.kept_flow;
    }
    const par::TimePoint done = par::now();
    detection.latency_ms = par::elapsed_ms(job.acquired, done);
    latency.add(detection.latency_ms);
    if (s.frames > 0) service_sum_ms += par::elapsed_ms(last_done, done);
    last_done = done;
    ++s.frames;
    if (deadline_ms > 0 && detection.latency_ms > deadline_ms) ++s.deadline_misses;
    if (detection.signal) {
      ++s.alarm_frames;
      if (!s.first_alarm_frame) {
        s.first_alarm_frame = detection.frame;
        s.first_alarm_time_s = detection.time_s;
      }
    }
    if (!job.frame->load_where_read()) s.busy_decode_ms += job.frame->decode_ms();
    s.busy_sm_ms += job.sm_ms;
    s.busy_of_ms += job.of_ms;
    s.busy_label_ms += std::accumulate(job.label_ms.begin(), job.label_ms.end(), 0.0);
    s.busy_conclude_ms += job.conclude_ms;
    sink(frame, detection);
    const double collector_ms = watch.elapsed_ms();
    const double collector_cpu_ms = cpu_watch.elapsed_ms();
    s.busy_collector_ms += collector_ms;
    s.collector_max_ms = std::max(s.collector_max_ms, collector_ms);
    s.busy_collector_cpu_ms += collector_cpu_ms;
    s.collector_cpu_max_ms = std::max(s.collector_cpu_max_ms, collector_cpu_ms);
  };

  try {
    auto run_farm = [&] {
      par::run_ordered_farm_relay(
          farm, [&] { return emitter(); }, [&](FrameJob& job) { return make_tasks(job, options); },
          [&](FrameJob& job) { return relay_tasks(job, detector, options); }, collect);
    };
    // The TBB farm runs in its own arena of `threads`; the sequential one gets an arena here so
    // that OpenCV's own parallel loops respect `threads` too.
    if (farm.backend == par::Backend::kSequential) {
      par::run_in_arena(options.threads, run_farm);
    } else {
      run_farm();
    }
  } catch (const cv::Exception& e) {
    // OpenCV rejects what our validation let through only for broken input.
    throw core::InputError(std::string("processing failed: ") + e.what());
  }

  s.dropped = emitter.dropped();
  s.interrupted = emitter.stopped();
  s.busy_emitter_ms = emitter.busy_ms();
  s.wall_s = std::chrono::duration<double>(last_done - start).count();
  s.throughput_fps = s.wall_s > 0 ? s.frames / s.wall_s : 0.0;
  s.service_ms = s.frames > 1 ? service_sum_ms / (s.frames - 1) : 0.0;
  s.latency_p50_ms = latency.p50();
  s.latency_p95_ms = latency.p95();
  s.latency_p99_ms = latency.p99();
  s.latency_max_ms = latency.max();
  s.latency_mean_ms = latency.mean();
  return s;
}

nlohmann::json RunSummary::to_json() const {
  auto opt = [](const auto& v) { return v ? nlohmann::json(*v) : nlohmann::json(); };
  return {{"frames", frames},
          {"dropped", dropped},
          {"alarm_frames", alarm_frames},
          {"first_alarm_frame", opt(first_alarm_frame)},
          {"first_alarm_time_s", opt(first_alarm_time_s)},
          {"interrupted", interrupted},
          {"deadline_misses", deadline_misses},
          {"wall_s", wall_s},
          {"throughput_fps", throughput_fps},
          {"service_ms", service_ms},
          {"latency_ms",
           {{"p50", latency_p50_ms},
            {"p95", latency_p95_ms},
            {"p99", latency_p99_ms},
            {"max", latency_max_ms},
            {"mean", latency_mean_ms}}},
          {"busy_ms",
           {{"emitter", busy_emitter_ms},
            {"decode", busy_decode_ms},
            {"stereo_matching", busy_sm_ms},
            {"optical_flow", busy_of_ms},
            {"labelling", busy_label_ms},
            {"obstacles", busy_conclude_ms},
            {"collector", busy_collector_ms}}},
          {"collector_max_ms", collector_max_ms},
          {"collector_cpu_ms", busy_collector_cpu_ms},
          {"collector_cpu_max_ms", collector_cpu_max_ms},
          {"config",
           {{"mode", mode},
            {"workers", workers},
            {"tiles", tiles},
            {"tokens", tokens},
            {"threads", threads},
            {"tile_flow", tile_flow},
            {"fps", pace_fps}}}};
}

std::string RunSummary::text() const {
  std::ostringstream s;
  s << std::fixed << std::setprecision(1);
  s << "frames processed  " << frames;
  if (pace_fps > 0) s << " (dropped " << dropped << ", deadline misses " << deadline_misses << ")";
  s << "\n";
  if (interrupted) s << "interrupted       yes: stopped taking frames on request\n";
  s << "alarm frames      " << alarm_frames << "\n";
  s << "first alarm       ";
  if (first_alarm_frame) {
    s << "frame " << *first_alarm_frame << " (t = " << std::setprecision(2) << *first_alarm_time_s
      << " s)\n"
      << std::setprecision(1);
  } else {
    s << "none\n";
  }
  s << "throughput        " << throughput_fps << " fps (" << wall_s << " s wall; mode " << mode
    << ", W " << workers << ", T " << tiles << ", tokens " << tokens << ")\n";
  s << "latency ms        p50 " << latency_p50_ms << "  p95 " << latency_p95_ms << "  p99 "
    << latency_p99_ms << "  max " << latency_max_ms << "\n";
  if (frames > 0) {
    const double n = frames;
    s << std::setprecision(2) << "busy ms / frame   decode " << busy_decode_ms / n << "  SM "
      << busy_sm_ms / n << "  OF " << busy_of_ms / n << "  labelling " << busy_label_ms / n
      << "  obstacles " << busy_conclude_ms / n << "  emitter " << busy_emitter_ms / n
      << "  collector " << busy_collector_ms / n << " (max " << collector_max_ms << "; CPU "
      << busy_collector_cpu_ms / n << ", max " << collector_cpu_max_ms << ")\n"
      << std::setprecision(1);
  }
  return s.str();
}

}  // namespace sg::pipeline
