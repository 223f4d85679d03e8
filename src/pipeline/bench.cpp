#include "sg/pipeline/bench.hpp"

#include <algorithm>

#include <sstream>

#include "sg/core/error.hpp"
#include "sg/io/memory_source.hpp"
#include "sg/par/metrics.hpp"
#include "sg/pipeline/plain_loop.hpp"
#include "sg/pipeline/runner.hpp"
#include "sg/sim/renderer.hpp"
#include "sg/vision/detector.hpp"

namespace sg::pipeline {
namespace {

/// The scenario at another resolution (same focal length, centred principal point).
sim::Scenario scaled(sim::Scenario s, cv::Size size, int frames) {
  s.camera.width = size.width;
  s.camera.height = size.height;
  s.camera.cx = (size.width - 1) / 2.0;
  s.camera.cy = (size.height - 1) / 2.0;
  s.frames = frames;
  return s;
}

/// Renders `frames` frames; scenarios shorter than that are played forwards then backwards.
std::vector<core::StereoFrame> render(const sim::Scenario& scenario, int frames) {
  const sim::Renderer renderer(scenario);
  std::vector<core::StereoFrame> out;
  out.reserve(frames);
  for (int i = 0; i < frames; ++i) {
    const int period = 2 * scenario.frames - 2;
    const int k = i % period;
    const int index = k < scenario.frames ? k : period - k;
    core::StereoFrame f = renderer.render(index, sim::TruthMapSet::kDangerOnly).frame;
    f.index = i;
    f.time_s = i / scenario.camera.fps;
    out.push_back(std::move(f));
  }
  return out;
}

struct Measured {
  BenchRow row;
  std::vector<bool> signals;
};

/// Sets OpenCV's thread count for the lifetime of the object.
class OpenCvThreads {
 public:
  explicit OpenCvThreads(int n) : saved_(cv::getNumThreads()) { cv::setNumThreads(n); }
  ~OpenCvThreads() { cv::setNumThreads(saved_); }
  OpenCvThreads(const OpenCvThreads&) = delete;
  OpenCvThreads& operator=(const OpenCvThreads&) = delete;

 private:
  int saved_;
};

/// The loop a user would write with OpenCV (PlainLoop: StereoBM, DIS, our labelling, one frame at a
/// time), timed per frame.
/// `opencv_threads` = 1 makes it truly sequential (the reference of DESIGN 8); -1 leaves OpenCV's
/// own parallel loops on (StereoBM splits each frame into stripes on all cores).
Measured run_baseline(const std::vector<core::StereoFrame>& frames, const core::Camera& camera,
                      const core::DetectorParams& params, int opencv_threads) {
  const OpenCvThreads threads(opencv_threads);
  PlainLoop loop(params, camera);

  Measured m;
  par::LatencyStats latency;
  const par::TimePoint start = par::now();
  for (size_t i = 0; i < frames.size(); ++i) {
    const par::TimePoint t0 = par::now();
    m.signals.push_back(loop.process(frames[i]).signal);
    latency.add(par::elapsed_ms(t0));
  }
  const double wall_s = par::elapsed_ms(start) / 1000.0;
  m.row.kind = opencv_threads == 1 ? "baseline" : "opencv-mt";
  m.row.frames = static_cast<int>(frames.size());
  m.row.fps = m.row.frames / wall_s;
  m.row.latency_p50_ms = latency.p50();
  m.row.latency_p99_ms = latency.p99();
  m.row.service_ms = latency.mean();
  m.row.workers = m.row.tiles = m.row.tokens = 1;
  return m;
}

Measured run_pipeline(const std::vector<core::StereoFrame>& frames, const core::Camera& camera,
                      const RunOptions& options) {
  io::MemorySource source(frames, camera);
  Measured m;
  const RunSummary s = run(source, options, [&m](const core::StereoFrame&,
                                                 const core::Detection& d) {
    m.signals.push_back(d.signal);
  });
  m.row.kind = options.pace_fps > 0 ? "paced" : "pipeline";
  m.row.workers = options.workers;
  m.row.tiles = options.tiles;
  m.row.tokens = s.tokens;
  m.row.pace_fps = options.pace_fps;
  m.row.frames = s.frames;
  m.row.dropped = s.dropped;
  m.row.deadline_misses = s.deadline_misses;
  m.row.fps = s.throughput_fps;
  m.row.latency_p50_ms = s.latency_p50_ms;
  m.row.latency_p99_ms = s.latency_p99_ms;
  m.row.service_ms = s.service_ms;
  return m;
}

}  // namespace

std::vector<std::string> validate(const BenchConfig& c) {
  std::vector<std::string> out;
  if (c.modes.empty()) out.push_back("bench.modes: at least one mode");
  if (c.workers.empty()) out.push_back("bench.workers: at least one value");
  for (int w : c.workers)
    if (w < 1 || w > 64) out.push_back("bench.workers=" + std::to_string(w) + ": must be in 1..64");
  if (c.tiles.empty()) out.push_back("bench.tiles: at least one value");
  for (int t : c.tiles)
    if (t < 1 || t > 64) out.push_back("bench.tiles=" + std::to_string(t) + ": must be in 1..64");
  if (c.resolutions.empty()) out.push_back("bench.resolutions: at least one");
  for (const cv::Size& s : c.resolutions)
    if (s.width < 64 || s.height < 64 || s.width > 4096 || s.height > 4096)
      out.push_back("bench.resolution=" + std::to_string(s.width) + "x" +
                    std::to_string(s.height) + ": each side must be in 64..4096");
  if (c.frames < 10) out.push_back("bench.frames=" + std::to_string(c.frames) + ": must be >= 10");
  for (double f : c.pace_fractions)
    if (!(f > 0 && f <= 10)) out.push_back("bench.pace: fractions must be in (0, 10]");
  if (c.capacity_runs < 1 || c.capacity_runs > 9)
    out.push_back("bench.capacity_runs=" + std::to_string(c.capacity_runs) + ": must be in 1..9");
  return out;
}

std::string same_detections_text(const BenchRow& r) {
  if (r.kind == "paced" && r.dropped > 0) return "n/a";
  return r.same_detections ? "yes" : "no";
}

std::string bench_csv_header() {
  return "kind,mode,width,height,workers,tiles,tokens,pace_fps,frames,dropped,deadline_misses,fps,"
         "speedup,latency_p50_ms,latency_p99_ms,service_ms,same_detections,speedup_1t";
}

std::string to_csv(const BenchRow& r) {
  std::ostringstream s;
  s << r.kind << "," << r.mode << "," << r.resolution.width << "," << r.resolution.height << ","
    << r.workers << "," << r.tiles << "," << r.tokens << "," << r.pace_fps << "," << r.frames
    << "," << r.dropped << "," << r.deadline_misses << "," << r.fps << "," << r.speedup << ","
    << r.latency_p50_ms << "," << r.latency_p99_ms << "," << r.service_ms << ","
    << same_detections_text(r) << "," << r.speedup_1t;
  return s.str();
}

/// Up to `frames` frames of `source` in memory, played forwards then backwards when shorter.
std::vector<core::StereoFrame> read_all(core::FrameSource& source, int frames) {
  std::vector<core::StereoFrame> read;
  while (static_cast<int>(read.size()) < frames) {
    std::optional<core::StereoFrame> f = source.next();
    if (!f) break;
    read.push_back(std::move(*f));
  }
  if (read.empty()) throw core::InputError("the bench input has no frames");
  std::vector<core::StereoFrame> out;
  const int n = static_cast<int>(read.size());
  const int period = std::max(1, 2 * n - 2);
  for (int i = 0; i < frames; ++i) {
    const int k = i % period;
    core::StereoFrame f = read[k < n ? k : period - k];
    f.index = i;
    f.time_s = i / source.camera().fps;
    out.push_back(std::move(f));
  }
  return out;
}

std::size_t best_for_pacing(const std::vector<BenchRow>& rows) {
  double top = 0.0;
  for (const BenchRow& r : rows)
    if (r.kind == "pipeline") top = std::max(top, r.fps);
  std::size_t best = rows.size();
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const BenchRow& r = rows[i];
    if (r.kind != "pipeline" || !(r.fps > 0.0) || r.fps < 0.95 * top) continue;
    if (best == rows.size() || r.latency_p99_ms < rows[best].latency_p99_ms) best = i;
  }
  return best;
}

std::vector<BenchRow> run_bench(const BenchConfig& config,
                                const std::function<void(const BenchRow&)>& on_row) {
  core::throw_if_invalid(validate(config), "invalid bench settings");
  const sim::Scenario base = sim::resolve_scenario(config.scenario);
  std::vector<BenchRow> rows;
  auto emit = [&](BenchRow row) {
    on_row(row);
    rows.push_back(std::move(row));
  };

  std::unique_ptr<core::FrameSource> input = config.open_input ? config.open_input() : nullptr;
  const std::vector<cv::Size> sizes =
      input ? std::vector<cv::Size>{{input->camera().width, input->camera().height}}
            : config.resolutions;
  for (size_t r = 0; r < sizes.size(); ++r) {
    const cv::Size size = sizes[r];
    const sim::Scenario scenario = scaled(base, size, base.frames);
    const core::Camera camera = input ? input->camera() : scenario.camera;
    const std::vector<core::StereoFrame> frames =
        input ? read_all(*input, config.frames) : render(scenario, config.frames);
    for (core::Mode mode : config.modes) {
      RunOptions options;
      options.params.bm.num_disparities = config.num_disparities;
      options.params.bm.matcher = config.matcher;
      core::select_detector(options.params, mode);  // longseq: its own matcher
      options.params.bm.cost = config.cost;
      options.threads = config.threads;
      options.tokens = config.tokens;
      core::throw_if_invalid(validate(options, camera), "invalid bench settings");

      Measured baseline = run_baseline(frames, camera, options.params, 1);
      baseline.row.mode = core::to_string(mode);
      baseline.row.resolution = size;
      Measured opencv_mt = run_baseline(frames, camera, options.params, -1);
      opencv_mt.row.mode = baseline.row.mode;
      opencv_mt.row.resolution = size;
      opencv_mt.row.same_detections = opencv_mt.signals == baseline.signals;
      // Speedups against the loop a user gets by default (OpenCV's own threads); the one-thread
      // loop stays as the second reference.
      auto set_speedups = [&](BenchRow& row) {
        row.speedup = row.fps / opencv_mt.row.fps;
        row.speedup_1t = row.fps / baseline.row.fps;
      };
      set_speedups(baseline.row);
      set_speedups(opencv_mt.row);
      emit(baseline.row);
      emit(opencv_mt.row);

      // The pipeline with `options` (W, T and any pace), as a row of `kind`; paced rows compare
      // detections with the baseline's only when nothing was dropped.
      auto measure = [&](const char* kind) {
        Measured m = run_pipeline(frames, camera, options);
        if (kind) m.row.kind = kind;
        m.row.mode = core::to_string(mode);
        m.row.resolution = size;
        set_speedups(m.row);
        m.row.same_detections = m.row.dropped == 0 && m.signals == baseline.signals;
        return m.row;
      };
      std::vector<BenchRow> swept;
      for (int w : config.workers) {
        for (int t : config.tiles) {
          options.workers = w;
          options.tiles = t;
          swept.push_back(measure(nullptr));
          emit(swept.back());
        }
      }
      const std::size_t best = best_for_pacing(swept);
      if (r != 0 || best == swept.size() || config.pace_fractions.empty()) continue;
      options.workers = swept[best].workers;
      options.tiles = swept[best].tiles;
      std::vector<double> capacity{swept[best].fps};
      for (int k = 1; k < config.capacity_runs; ++k) {
        const BenchRow row = measure("capacity");
        emit(row);
        capacity.push_back(row.fps);
      }
      std::sort(capacity.begin(), capacity.end());
      const double capacity_fps = capacity[capacity.size() / 2];
      const double spread = (capacity.back() - capacity.front()) / capacity_fps;
      auto refer_to_capacity = [&](BenchRow row) {
        row.capacity_fps = capacity_fps;
        row.capacity_spread = spread;
        row.capacity_runs = static_cast<int>(capacity.size());
        emit(row);
      };
      for (double fraction : config.pace_fractions) {
        options.pace_fps = fraction * capacity_fps;
        refer_to_capacity(measure(nullptr));
        options.pace_fps = 0;
      }
      // The machine's speed after the paced rows: a pace that was 80 % of the capacity measured
      // before them is not 80 % of a machine that slowed while they ran.
      if (config.capacity_runs > 1) refer_to_capacity(measure("recheck"));
    }
  }
  return rows;
}

}  // namespace sg::pipeline
