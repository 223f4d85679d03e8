// The obstacle pipeline on the par skeletons: every (W, T, tokens, threads) gives the detections
// of the sequential reference; errors anywhere end the run with that error; pacing drops frames
// instead of queueing them.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <stdexcept>

#include "sg/core/error.hpp"
#include "sg/io/events.hpp"
#include "sg/io/memory_source.hpp"
#include "sg/pipeline/dropping_source.hpp"
#include "sg/pipeline/plain_loop.hpp"
#include "sg/pipeline/runner.hpp"
#include "sg/pipeline/stereo_evaluation.hpp"
#include "sg/sim/renderer.hpp"

namespace sg::pipeline {
namespace {

#if defined(__SANITIZE_THREAD__)
// Debian's OpenCV is not built with ThreadSanitizer and hands its own parallel loops to TBB, where
// TSan cannot see the synchronisation. Under TSan OpenCV's internal loops run on the calling
// thread, so the reports left are about our farm and tiles, which is what this build checks.
const bool kOpenCvSerial = [] {
  cv::setNumThreads(0);
  return true;
}();
// Under TSan a run is 20-40x slower: the configuration tests keep the ones that put each part of
// the skeleton under concurrent use (the farm, tiles, both, the tightest token bound, more workers
// than cores); the release stage runs every configuration listed.
constexpr bool kSanitizedThreads = true;
#else
constexpr bool kSanitizedThreads = false;
#endif

/// The configurations to run: all of them, or under TSan the first `tsan_count`.
template <typename T, size_t N>
std::vector<T> configurations(const T (&all)[N], size_t tsan_count) {
  return {all, all + (kSanitizedThreads ? std::min(tsan_count, N) : N)};
}

/// A built-in scenario at 321x241 (odd size, f = 250 px), started nearer so that 36 frames hold
/// an approach, rendered once.
struct Clip {
  core::Camera camera;
  std::vector<core::StereoFrame> frames;
};

Clip render_clip(const std::string& name, double z_shift) {
  sim::Scenario s = sim::builtin_scenario(name);
  s.camera.width = 321;
  s.camera.height = 241;
  s.camera.focal_px = 250;
  s.camera.cx = 160;
  s.camera.cy = 120;
  s.frames = 36;
  for (auto& box : s.obstacles) box.position_m[2] -= z_shift;
  const sim::Renderer renderer(s);
  Clip clip{s.camera, {}};
  for (int i = 0; i < s.frames; ++i) clip.frames.push_back(renderer.render(i).frame);
  return clip;
}

const Clip& head_on() {
  static const Clip clip = render_clip("head-on", 9.0);
  return clip;
}
const Clip& crossing() {
  static const Clip clip = render_clip("crossing", 0.0);
  return clip;
}

/// Every detection of a run as its event line (without latency), in order.
std::vector<std::string> detections(const Clip& clip, const RunOptions& options,
                                    RunSummary* summary = nullptr) {
  io::MemorySource source(clip.frames, clip.camera);
  std::vector<std::string> lines;
  const RunSummary s = run(source, options, [&](const core::StereoFrame& f,
                                                const core::Detection& d) {
    EXPECT_EQ(f.index, d.frame);
    lines.push_back(io::detection_to_json(d, /*timing=*/false).dump());
  });
  if (summary) *summary = s;
  return lines;
}

RunOptions options_for(core::Mode mode) {
  RunOptions o;
  o.params.mode = mode;
  o.params.signal.min_area_px = 40;  // the clip is a quarter of VGA
  o.params.signal.region_min_px = 40;
  return o;
}

class EveryConfiguration : public ::testing::TestWithParam<core::Mode> {};

TEST_P(EveryConfiguration, GivesTheSequentialDetections) {
  // TSan: the head-on clip only (the crossing one puts the same skeleton under the same load).
  std::vector<const Clip*> clips{&head_on()};
  if (!kSanitizedThreads) clips.push_back(&crossing());
  for (const Clip* clip : clips) {
    const RunOptions reference = options_for(GetParam());
    const std::vector<std::string> expected = detections(*clip, reference);
    ASSERT_EQ(expected.size(), clip->frames.size());
    // (arena threads, W, T, tokens): the farm and tiles at once with more workers than cores and
    // the tightest token bound, the farm alone, a one-thread arena that must still get through
    // (TSan runs these three); then tiles alone, one-thread farm, many tiles, many tokens and the
    // default arena.
    using Config = std::array<int, 4>;
    const Config all[] = {{2, 3, 2, 1}, {2, 2, 1, 0}, {1, 1, 3, 0}, {2, 1, 2, 0},
                          {1, 2, 1, 0}, {2, 2, 5, 0}, {2, 3, 1, 6}, {0, 2, 2, 0}};
    for (const Config& c : configurations(all, 3)) {
      RunOptions o = reference;
      o.threads = c[0];
      o.workers = c[1];
      o.tiles = c[2];
      o.tokens = c[3];
      EXPECT_EQ(detections(*clip, o), expected)
          << "threads " << c[0] << " W " << c[1] << " T " << c[2] << " tokens " << c[3];
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Modes, EveryConfiguration,
                         ::testing::Values(core::Mode::kStereo, core::Mode::kStereoFlow),
                         [](const auto& info) {
                           return info.param == core::Mode::kStereo ? "Stereo" : "StereoFlow";
                         });

TEST(Pipeline, LongSeqMatcherTilesAndWorkersGiveTheSequentialDetections) {
  // LongSeq's rows are independent: row tiles and workers change nothing, in both modes (TSan:
  // Stereo-Flow only; the matcher's tiles are the same code in either mode).
  std::vector<core::Mode> modes{core::Mode::kStereoFlow};
  if (!kSanitizedThreads) modes.push_back(core::Mode::kStereo);
  for (const core::Mode mode : modes) {
    RunOptions reference = options_for(mode);
    reference.params.bm.matcher = core::Matcher::kLongSeq;
    const std::vector<std::string> expected = detections(head_on(), reference);
    ASSERT_EQ(expected.size(), head_on().frames.size());
    const auto fired = std::count_if(expected.begin(), expected.end(), [](const std::string& l) {
      return l.find("\"signal\":true") != std::string::npos;
    });
    EXPECT_GT(fired, 0) << core::to_string(mode);  // the box comes at the camera
    const std::pair<int, int> all[] = {{2, 2}, {2, 1}, {1, 3}};  // TSan: both at once only
    for (const auto& [w, t] : configurations(all, 1)) {
      RunOptions o = reference;
      o.workers = w;
      o.tiles = t;
      EXPECT_EQ(detections(head_on(), o), expected)
          << core::to_string(mode) << " W " << w << " T " << t;
    }
  }
}

/// The detectors the thesis surveys (vision/surveyed.hpp).
class SurveyedDetector : public ::testing::TestWithParam<core::Mode> {};

TEST_P(SurveyedDetector, FiresOnTheApproachAndEveryConfigurationGivesTheSequentialDetections) {
  // Each computes only what it needs (SM, OF, neither), in the farm's tasks; its labelling runs
  // once per frame; workers, tiles and tokens change nothing.
  RunOptions reference = options_for(GetParam());
  core::select_detector(reference.params, GetParam());
  RunSummary s;
  const std::vector<std::string> expected = detections(head_on(), reference, &s);
  ASSERT_EQ(expected.size(), head_on().frames.size());
  EXPECT_GT(s.alarm_frames, 0) << core::to_string(GetParam());
  const core::Needs need = core::needs(GetParam());
  EXPECT_EQ(s.busy_sm_ms > 0, need.disparity);
  EXPECT_EQ(s.busy_of_ms > 0, need.flow);
  const std::tuple<int, int, int> all[] = {{3, 2, 1}, {2, 2, 0}, {2, 1, 0}, {1, 3, 0}};
  for (const auto& [w, t, tokens] : configurations(all, 1)) {  // TSan: the first, all at once
    RunOptions o = reference;
    o.workers = w;
    o.tiles = t;
    o.tokens = tokens;
    EXPECT_EQ(detections(head_on(), o), expected) << "W " << w << " T " << t << " tok " << tokens;
  }
}

INSTANTIATE_TEST_SUITE_P(Detectors, SurveyedDetector,
                         ::testing::Values(core::Mode::kMotionParallax, core::Mode::kRelativeSize,
                                           core::Mode::kElevationMap, core::Mode::kSceneFlowSeg,
                                           core::Mode::kLongSeq),
                         [](const auto& info) {
                           std::string name = core::to_string(info.param);
                           name.erase(std::remove(name.begin(), name.end(), '-'), name.end());
                           return name;
                         });

TEST_P(EveryConfiguration, PlainLoopGivesThePipelineDetections) {
  // The baseline of bench and bench_process.sh does the same work: StereoBM, DIS ultrafast and
  // the detector, one frame at a time.
  // Without the left-right check and the left band: StereoBM's (validateDisparity) and the fast matcher's differ in
  // which pixels they drop (StereoAccuracyData.FastIsNoWorseThanBmSparseAndDense).
  for (const Clip* clip : {&head_on(), &crossing()}) {
    RunOptions options = options_for(GetParam());
    options.params.bm.lr_max_diff = -1;
    options.params.bm.left_band = false;  // the loop is StereoBM alone
    options.params.bm.coarse_fill = false;
    options.params.bm.periodic_ratio = 0.0;  // nor drops the matches on repeating texture
    const std::vector<std::string> expected = detections(*clip, options);
    PlainLoop loop(options.params, clip->camera);
    std::vector<std::string> got;
    for (const core::StereoFrame& f : clip->frames)
      got.push_back(io::detection_to_json(loop.process(f), /*timing=*/false).dump());
    EXPECT_EQ(got, expected);
  }
}

// eval --stereo's rows: each matcher alone, unless its label names the fill or the periodic check.
TEST(Pipeline, StereoEvaluationRowsAreTheMatchersAloneUnlessTheLabelSaysOtherwise) {
  core::BmParams base;
  base.coarse_fill = true;
  for (const char* label : {"bm", "sgbm", "fast", "fast-census"}) {
    const StereoMatcherEntry e = parse_matcher_entry(label, base);
    EXPECT_FALSE(e.params.coarse_fill) << label;
    EXPECT_EQ(e.params.periodic_ratio, 0.0) << label;
  }
  EXPECT_TRUE(parse_matcher_entry("fast-filled", base).params.coarse_fill);
  EXPECT_EQ(parse_matcher_entry("fast-periodic", base).params.periodic_ratio,
            core::BmParams{}.periodic_ratio);
  base.periodic_ratio = 0.0;  // --config turned it off: the row still shows the check
  EXPECT_GT(parse_matcher_entry("fast-periodic", base).params.periodic_ratio, 0.0);
  base.periodic_ratio = 0.45;
  EXPECT_EQ(parse_matcher_entry("fast-periodic", base).params.periodic_ratio, 0.45);
  EXPECT_THROW(parse_matcher_entry("fast-striped", base), core::InputError);
}

TEST(Pipeline, HeadOnClipFiresAndCrossingClipIsAnApproachOnlyInStereoMode) {
  // Guards the test data: the identity test above must compare runs that do detect something.
  RunSummary s;
  detections(head_on(), options_for(core::Mode::kStereo), &s);
  EXPECT_GT(s.alarm_frames, 0);
  EXPECT_EQ(s.frames, 36);
}

TEST(DroppingSource, LosesEveryNthFrameKeepingIndicesAndTimes) {
  std::vector<core::StereoFrame> frames(12);
  for (int i = 0; i < 12; ++i) {
    frames[i].index = i;
    frames[i].time_s = i * 0.1;
  }
  io::MemorySource inner(frames, core::Camera{});
  DroppingSource source(inner, 5);
  std::vector<int> seen;
  while (auto f = source.next()) {
    seen.push_back(f->index);
    EXPECT_DOUBLE_EQ(f->time_s, f->index * 0.1);
  }
  EXPECT_EQ(seen, (std::vector<int>{0, 1, 2, 3, 5, 6, 7, 8, 10, 11}));
  EXPECT_EQ(source.dropped(), 2);
}

// Stereo-Flow under 20 % drops: the chain survives them, so the head-on clip still fires.
TEST(Pipeline, StereoFlowStillFiresWithEveryFifthFrameDropped) {
  io::MemorySource inner(head_on().frames, head_on().camera);
  DroppingSource source(inner, 5);
  RunOptions o = options_for(core::Mode::kStereoFlow);
  int alarms = 0;
  const RunSummary s = run(
      source, o, [&](const core::StereoFrame&, const core::Detection& d) { alarms += d.signal; });
  EXPECT_GT(alarms, 0);
  // Frames missing from the source's indices (as a live camera's) count as dropped.
  EXPECT_EQ(s.dropped, source.dropped());
  EXPECT_EQ(s.frames + s.dropped, static_cast<int>(head_on().frames.size()));
}

TEST(Pipeline, EmptyStream) {
  const std::vector<core::StereoFrame> none;
  io::MemorySource source(none, core::Camera{});
  int calls = 0;
  RunOptions o;
  o.workers = 2;
  o.tiles = 2;
  const RunSummary s = run(source, o, [&](const auto&, const auto&) { ++calls; });
  EXPECT_EQ(calls, 0);
  EXPECT_EQ(s.frames, 0);
}

/// Counts the frames the emitter takes from a clip.
class TakenCounter : public core::FrameSource {
 public:
  explicit TakenCounter(const Clip& clip) : memory_(clip.frames, clip.camera) {}
  std::optional<core::StereoFrame> next() override {
    std::optional<core::StereoFrame> frame = memory_.next();
    if (frame) ++taken_;
    return frame;
  }
  const core::Camera& camera() const override { return memory_.camera(); }
  int taken() const { return taken_; }

 private:
  io::MemorySource memory_;
  int taken_ = 0;
};

TEST(Pipeline, StopRequestEndsTheRunAfterTheFramesInFlight) {
  const Clip& clip = head_on();
  const RunOptions reference = options_for(core::Mode::kStereoFlow);
  const std::vector<std::string> full = detections(clip, reference);
  constexpr int kStopAfter = 5;
  // (W, T, tokens): sequential, a farm with its automatic tokens, a farm with many in flight.
  const int configs[][3] = {{1, 1, 0}, {2, 2, 0}, {3, 1, 8}};
  for (const auto& c : configs) {
    RunOptions o = reference;
    o.workers = c[0];
    o.tiles = c[1];
    o.tokens = c[2];
    std::atomic<bool> stop{false};
    o.stop = &stop;
    TakenCounter source(clip);
    std::vector<std::string> lines;
    const RunSummary s = run(source, o, [&](const core::StereoFrame&, const core::Detection& d) {
      lines.push_back(io::detection_to_json(d, /*timing=*/false).dump());
      if (static_cast<int>(lines.size()) == kStopAfter) stop = true;
    });
    const std::string config = "W " + std::to_string(c[0]) + " T " + std::to_string(c[1]) +
                               " tokens " + std::to_string(c[2]);
    EXPECT_TRUE(s.interrupted) << config;
    // Every frame taken is finished and delivered; no more than the tokens follow the request.
    EXPECT_EQ(source.taken(), static_cast<int>(lines.size())) << config;
    EXPECT_EQ(s.frames, static_cast<int>(lines.size())) << config;
    EXPECT_GE(s.frames, kStopAfter) << config;
    EXPECT_LE(s.frames, kStopAfter + effective_tokens(o)) << config;
    // In order and complete: the first frames of the uninterrupted run, detection for detection.
    ASSERT_LE(lines.size(), full.size());
    EXPECT_EQ(lines, std::vector<std::string>(full.begin(), full.begin() + lines.size()))
        << config;
  }
}

TEST(Pipeline, StopRequestedBeforeTheStartTakesNoFrame) {
  std::atomic<bool> stop{true};
  RunOptions o = options_for(core::Mode::kStereo);
  o.stop = &stop;
  TakenCounter source(head_on());
  int calls = 0;
  const RunSummary s = run(source, o, [&](const auto&, const auto&) { ++calls; });
  EXPECT_TRUE(s.interrupted);
  EXPECT_EQ(s.frames, 0);
  EXPECT_EQ(calls, 0);
  EXPECT_EQ(source.taken(), 0);
}

TEST(Pipeline, RunToTheEndIsNotInterrupted) {
  std::atomic<bool> stop{false};
  RunOptions o = options_for(core::Mode::kStereo);
  o.stop = &stop;
  RunSummary s;
  EXPECT_EQ(detections(head_on(), o, &s).size(), head_on().frames.size());
  EXPECT_FALSE(s.interrupted);
  EXPECT_FALSE(s.to_json().at("interrupted").get<bool>());
}

/// Delivers `good` frames of a clip, then throws.
class FailingSource : public core::FrameSource {
 public:
  FailingSource(const Clip& clip, int good) : clip_(clip), good_(good) {}
  std::optional<core::StereoFrame> next() override {
    if (next_ == good_) throw core::InputError("frame " + std::to_string(next_) + " is broken");
    return clip_.frames[next_++];
  }
  const core::Camera& camera() const override { return clip_.camera; }

 private:
  const Clip& clip_;
  int good_, next_ = 0;
};

TEST(Pipeline, BrokenInputEndsTheRunWithItsError) {
  for (int workers : {1, 2}) {
    FailingSource source(head_on(), 7);
    RunOptions o;
    o.workers = workers;
    o.tiles = workers;
    std::vector<int> seen;
    EXPECT_THROW(run(source, o, [&](const auto&, const core::Detection& d) {
                   seen.push_back(d.frame);
                 }),
                 core::InputError);
    for (size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], static_cast<int>(i));
    EXPECT_LE(seen.size(), 7u);
  }
}

TEST(Pipeline, MismatchedFrameEndsTheRunWithAnInputError) {
  std::vector<core::StereoFrame> frames = head_on().frames;
  frames.resize(6);
  frames[3].right = frames[3].right(cv::Rect(0, 0, 100, 100)).clone();
  io::MemorySource source(frames, head_on().camera);
  RunOptions o;
  o.workers = 2;
  EXPECT_THROW(run(source, o, [](const auto&, const auto&) {}), core::InputError);
}

TEST(Pipeline, ExceptionInTheCollectorSurfaces) {
  io::MemorySource source(head_on().frames, head_on().camera);
  RunOptions o;
  o.workers = 2;
  o.tiles = 3;
  EXPECT_THROW(run(source, o,
                   [](const auto&, const core::Detection& d) {
                     if (d.frame == 5) throw std::runtime_error("sink failed");
                   }),
               std::runtime_error);
}

TEST(Pipeline, PacedFasterThanPossibleDropsAndCountsFrames) {
  io::MemorySource source(head_on().frames, head_on().camera);
  RunOptions o;
  o.pace_fps = 100000;  // a frame every 10 us: far beyond any configuration's capacity
  o.workers = 2;
  const RunSummary s = run(source, o, [](const auto&, const auto&) {});
  EXPECT_GT(s.dropped, 0);
  EXPECT_EQ(s.frames + s.dropped, 36);
  EXPECT_GT(s.deadline_misses, 0);
}

/// Pending frames of a clip that count their loads; `where_read` sets load_where_read.
class CountingSource : public core::FrameSource {
 public:
  CountingSource(const Clip& clip, bool where_read) : clip_(clip), where_read_(where_read) {}
  std::optional<core::StereoFrame> next() override { throw std::logic_error("next_pending only"); }
  std::optional<core::PendingFrame> next_pending() override {
    if (next_ == static_cast<int>(clip_.frames.size())) return std::nullopt;
    const core::StereoFrame& frame = clip_.frames[static_cast<size_t>(next_++)];
    core::PendingFrame p{frame.index, frame.time_s, [this, &frame] {
                           loads_.fetch_add(1);
                           return frame;
                         }};
    p.load_where_read = where_read_;
    return p;
  }
  const core::Camera& camera() const override { return clip_.camera; }
  int loads() const { return loads_.load(); }

 private:
  const Clip& clip_;
  bool where_read_;
  int next_ = 0;
  std::atomic<int> loads_{0};
};

TEST(Pipeline, PacedRunLoadsTheFramesItKeepsOnlyWhereverTheyLoad) {
  for (bool where_read : {false, true}) {
    CountingSource source(head_on(), where_read);
    RunOptions o;
    o.pace_fps = 100000;
    o.workers = 2;
    o.tiles = 2;
    const RunSummary s = run(source, o, [](const auto&, const auto&) {});
    EXPECT_GT(s.dropped, 0) << where_read;
    EXPECT_EQ(s.frames + s.dropped, 36) << where_read;
    EXPECT_EQ(source.loads(), s.frames) << where_read;
  }
}

TEST(Pipeline, FileInputNeverDrops) {
  RunSummary s;
  RunOptions o;
  o.workers = 3;
  o.tokens = 1;
  detections(head_on(), o, &s);
  EXPECT_EQ(s.dropped, 0);
  EXPECT_EQ(s.frames, 36);
  EXPECT_EQ(s.deadline_misses, 0);  // not paced: no deadline
}

TEST(Pipeline, InvalidOptionsAreNamed) {
  const core::Camera cam;
  RunOptions o;
  o.workers = 0;
  o.tiles = 0;
  o.tokens = -1;
  o.pace_fps = -5;
  std::string all;
  for (const auto& p : validate(o, cam)) all += p + "\n";
  EXPECT_NE(all.find("workers=0"), std::string::npos) << all;
  EXPECT_NE(all.find("tiles=0"), std::string::npos) << all;
  EXPECT_NE(all.find("tokens=-1"), std::string::npos) << all;
  EXPECT_NE(all.find("fps=-5"), std::string::npos) << all;
  o = RunOptions{};
  o.tiles = 61;  // 480 / 8 = 60 tiles at most
  EXPECT_EQ(validate(o, cam).size(), 1u);
  EXPECT_EQ(effective_tokens(RunOptions{}), 2);
}

TEST(Pipeline, AutomaticTokensKeepAFrameReadyBeyondTheWorkersPacedOrNot) {
  RunOptions o;
  o.workers = 3;
  EXPECT_EQ(effective_tokens(o), 4);
  o.pace_fps = 30;  // the extra frame is held until its capture, off the workers
  EXPECT_EQ(effective_tokens(o), 4);
  o.tokens = 5;  // an explicit count stands either way
  EXPECT_EQ(effective_tokens(o), 5);
  o.pace_fps = 0;
  EXPECT_EQ(effective_tokens(o), 5);
}

TEST(Pipeline, SummaryCountsAndPercentiles) {
  RunSummary s;
  RunOptions o = options_for(core::Mode::kStereo);
  o.workers = 2;
  detections(head_on(), o, &s);
  EXPECT_EQ(s.frames, 36);
  EXPECT_LE(s.latency_p50_ms, s.latency_p95_ms);
  EXPECT_LE(s.latency_p95_ms, s.latency_p99_ms);
  EXPECT_LE(s.latency_p99_ms, s.latency_max_ms);
  EXPECT_GT(s.busy_sm_ms, 0.0);
  EXPECT_EQ(s.busy_of_ms, 0.0);  // Stereo mode computes no flow
  const auto j = s.to_json();
  EXPECT_EQ(j["config"]["workers"], 2);
  EXPECT_EQ(j["frames"], 36);
}

// The heap a run holds: the history of the longest gap plus the frames in flight; Stereo-Flow
// keeps flow and edges too; unknown sizes prefault nothing.
TEST(HeapEstimate, GrowsWithHistoryTokensAndMode) {
  RunOptions o;
  o.params.mode = core::Mode::kStereoFlow;
  o.params.scene_flow.gaps = {1, 4, 10, 20};
  const std::size_t px = 640 * 480;
  EXPECT_EQ(heap_estimate(o, 640, 480), px * (13 * 20 + 48 * 3));
  EXPECT_EQ(heap_estimate(o, 0, 480), 0u);
  RunOptions stereo = o;
  stereo.params.mode = core::Mode::kStereo;
  stereo.params.stereo.gaps = {1, 5, 15};
  EXPECT_EQ(heap_estimate(stereo, 640, 480), px * (4 * 15 + 48 * 3));
  RunOptions wide = o;
  wide.workers = 3;
  EXPECT_GT(heap_estimate(wide, 640, 480), heap_estimate(o, 640, 480));
}

}  // namespace
}  // namespace sg::pipeline
