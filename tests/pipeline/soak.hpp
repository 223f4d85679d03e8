#pragma once
// The soak harness (label soak, see test_soak.cpp): a scenario rendered once, looped in memory to
// many frames through the full pipeline, with the resident memory sampled and every event checked.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "sg/core/source.hpp"
#include "sg/io/events.hpp"
#include "sg/pipeline/runner.hpp"
#include "sg/sim/renderer.hpp"

namespace sg::pipeline::soak {

/// Resident set size of this process, KiB (second field of /proc/self/statm); -1 if unreadable.
inline long resident_kib() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return -1;
  long size_pages = 0, resident_pages = 0;
  const int got = std::fscanf(f, "%ld %ld", &size_pages, &resident_pages);
  std::fclose(f);
  if (got != 2) return -1;
  return resident_pages * (::sysconf(_SC_PAGESIZE) / 1024);
}

/// Hands out `total` frames cycling through `clip`, numbered 0 .. total - 1 with time index / fps,
/// sharing the clip's pixels (no copy, no rendering).
class LoopSource : public core::FrameSource {
 public:
  LoopSource(const std::vector<core::StereoFrame>& clip, const core::Camera& camera, int total,
             std::function<void(core::StereoFrame&)> tamper = {})
      : clip_(clip), camera_(camera), total_(total), tamper_(std::move(tamper)) {}
  std::optional<core::StereoFrame> next() override {
    if (next_ >= total_) return std::nullopt;
    core::StereoFrame f = clip_[static_cast<std::size_t>(next_) % clip_.size()];
    f.index = next_;
    f.time_s = next_ / camera_.fps;
    ++next_;
    if (tamper_) tamper_(f);
    return f;
  }
  const core::Camera& camera() const override { return camera_; }
  int size() const override { return total_; }
  int handed_out() const { return next_; }

 private:
  const std::vector<core::StereoFrame>& clip_;
  core::Camera camera_;
  int total_;
  std::function<void(core::StereoFrame&)> tamper_;
  int next_ = 0;
};

struct Config {
  int frames = 100000;      ///< frames through the pipeline
  int width = 320;          ///< px; the scenario's camera is scaled to this size
  int height = 240;         ///< px
  int loop = 60;            ///< distinct frames rendered once and looped
  int warmup = 5000;        ///< frames before the memory baseline is taken
  int sample_every = 1000;  ///< frames between two memory samples
  RunOptions options;       ///< W 2, T 2, Stereo-Flow by default (see default_config)
  /// Harness self-test only: alters each frame as the source hands it out (e.g. renumbers one, as
  /// a source or pipeline that loses or repeats a frame would look to the sink).
  std::function<void(core::StereoFrame&)> tamper;
};

/// The acceptance configuration, overridable by environment variables: SG_SOAK_FRAMES,
/// SG_SOAK_SIZE (WxH), SG_SOAK_LOOP, SG_SOAK_WARMUP.
inline Config config_from_env() {
  Config c;
  c.options.params.mode = core::Mode::kStereoFlow;
  c.options.workers = 2;
  c.options.tiles = 2;
  if (const char* v = std::getenv("SG_SOAK_FRAMES")) c.frames = std::atoi(v);
  if (const char* v = std::getenv("SG_SOAK_SIZE")) std::sscanf(v, "%dx%d", &c.width, &c.height);
  if (const char* v = std::getenv("SG_SOAK_LOOP")) c.loop = std::atoi(v);
  if (const char* v = std::getenv("SG_SOAK_WARMUP")) c.warmup = std::atoi(v);
  return c;
}

struct Result {
  int frames_in = 0;        ///< frames the source handed out
  int frames_out = 0;       ///< detections delivered to the sink
  int out_of_order = 0;     ///< detections or events whose frame was not the next expected one
  int dropped = 0;          ///< RunSummary::dropped
  int warmup_frames = 0;    ///< Config::warmup
  long baseline_kib = 0;    ///< resident memory at the end of the warm-up
  long peak_after_kib = 0;  ///< largest sample after the warm-up
  std::vector<std::pair<int, long>> samples;  ///< (frames done, resident KiB)
  RunSummary summary;
  /// Trend after the warm-up: mean of the last quarter of the samples taken after it minus the
  /// mean of the first quarter, KiB. Means rather than single samples, so that the allocator
  /// handing pages back and forth (a spike of a few MiB that goes away) is not taken for a leak,
  /// while a leak of L bytes per frame shows as about L * 3/4 * (frames - warm-up).
  long growth_kib() const {
    std::vector<long> after;
    for (const auto& [frames, kib] : samples)
      if (frames > warmup_frames) after.push_back(kib);
    if (after.size() < 4) return peak_after_kib - baseline_kib;
    const std::size_t q = after.size() / 4;
    double first = 0, last = 0;
    for (std::size_t i = 0; i < q; ++i) {
      first += after[i];
      last += after[after.size() - 1 - i];
    }
    return static_cast<long>((last - first) / static_cast<double>(q));
  }
};

/// The head-on scenario with its camera scaled to width x height, `loop` frames rendered once.
inline std::vector<core::StereoFrame> render_loop(const Config& c, core::Camera& camera) {
  sim::Scenario s = sim::builtin_scenario("head-on");
  const double scale = static_cast<double>(c.width) / s.camera.width;
  s.camera.focal_px *= scale;
  s.camera.cx = (c.width - 1) / 2.0;
  s.camera.cy = (c.height - 1) / 2.0;
  s.camera.width = c.width;
  s.camera.height = c.height;
  s.frames = c.loop;
  camera = s.camera;
  const sim::Renderer renderer(s);
  std::vector<core::StereoFrame> frames;
  for (int i = 0; i < c.loop; ++i) frames.push_back(renderer.render(i).frame);
  return frames;
}

/// Runs the soak. `per_frame` (may be empty) is called in the sink after the checks; the harness
/// self-test uses it to leak on purpose.
inline Result run_soak(const Config& c, const std::function<void()>& per_frame = {}) {
  core::Camera camera;
  const std::vector<core::StereoFrame> clip = render_loop(c, camera);
  RunOptions o = c.options;
  const double area = static_cast<double>(c.width) * c.height / (640.0 * 480.0);
  o.params.signal.min_area_px = std::max(1, static_cast<int>(o.params.signal.min_area_px * area));
  o.params.signal.region_min_px =
      std::max(1, static_cast<int>(o.params.signal.region_min_px * area));
  LoopSource source(clip, camera, c.frames, c.tamper);
  Result r;
  r.warmup_frames = c.warmup;
  r.samples.emplace_back(0, resident_kib());
  r.summary = run(source, o, [&](const core::StereoFrame& f, const core::Detection& d) {
    // One event per frame, in order: the detection, its frame and its JSON event line all carry
    // the next frame number.
    const nlohmann::json event = io::detection_to_json(d, /*timing=*/true);
    const int expected = r.frames_out;
    if (f.index != expected || d.frame != expected || event.at("frame").get<int>() != expected) {
      ++r.out_of_order;
    }
    ++r.frames_out;
    if (per_frame) per_frame();
    if (r.frames_out % c.sample_every == 0 || r.frames_out == c.warmup) {
      const long rss = resident_kib();
      r.samples.emplace_back(r.frames_out, rss);
      if (r.frames_out == c.warmup) r.baseline_kib = rss;
      if (r.frames_out > c.warmup) r.peak_after_kib = std::max(r.peak_after_kib, rss);
    }
  });
  r.frames_in = source.handed_out();
  r.dropped = r.summary.dropped;
  return r;
}

/// Why a soak run fails, one line per reason (empty: it passes): frames lost, duplicated or out of
/// order, frames dropped, memory unreadable, or resident memory grown by more than
/// `max_growth_mb` after the warm-up (Result::growth_kib). test_soak asserts it is empty;
/// test_soak_harness checks that it is not for a run that leaks or renumbers a frame.
inline std::vector<std::string> failures(const Config& c, const Result& r, double max_growth_mb) {
  std::vector<std::string> out;
  auto add = [&out](const std::string& what) { out.push_back(what); };
  if (r.frames_in != c.frames) add("frames in " + std::to_string(r.frames_in));
  if (r.frames_out != c.frames) add("frames out " + std::to_string(r.frames_out));
  if (r.summary.frames != c.frames) add("summary frames " + std::to_string(r.summary.frames));
  if (r.out_of_order != 0) add("out of order " + std::to_string(r.out_of_order));
  if (r.dropped != 0) add("dropped " + std::to_string(r.dropped));
  if (r.baseline_kib <= 0) add("/proc/self/statm unreadable");
  if (r.growth_kib() / 1024.0 > max_growth_mb) {
    add("memory grew by " + std::to_string(r.growth_kib() / 1024.0) + " MiB after the warm-up");
  }
  return out;
}

}  // namespace sg::pipeline::soak
