// Soak (label soak, not in the default run; `ctest --preset soak`): a scenario looped to 100k
// frames through the full pipeline (W 2, T 2, Stereo-Flow) with flat resident memory and one
// event per frame, in order. SG_SOAK_FRAMES, SG_SOAK_SIZE (WxH, default 320x240), SG_SOAK_LOOP,
// SG_SOAK_WARMUP and SG_SOAK_MAX_GROWTH_MB (default 4) change the run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "soak.hpp"

namespace sg::pipeline::soak {
namespace {

TEST(Soak, LoopedScenarioKeepsMemoryFlatAndEveryFrameInOrder) {
  const Config c = config_from_env();
  double max_growth_mb = 4.0;
  if (const char* v = std::getenv("SG_SOAK_MAX_GROWTH_MB")) max_growth_mb = std::atof(v);
  ASSERT_GT(c.frames, c.warmup) << "SG_SOAK_FRAMES must exceed SG_SOAK_WARMUP";

  const Result r = run_soak(c);

  std::printf("soak: %d frames %dx%d (loop of %d), W %d T %d %s, tokens %d\n", c.frames, c.width,
              c.height, c.loop, r.summary.workers, r.summary.tiles, r.summary.mode.c_str(),
              r.summary.tokens);
  std::printf("soak: frames in %d, out %d, out of order %d, dropped %d\n", r.frames_in,
              r.frames_out, r.out_of_order, r.dropped);
  const std::size_t step = std::max<std::size_t>(1, r.samples.size() / 20);
  for (std::size_t i = 0; i < r.samples.size(); ++i) {
    const auto& [frames, kib] = r.samples[i];
    if (i % step == 0 || frames == c.warmup || i + 1 == r.samples.size()) {
      std::printf("soak: rss after %6d frames: %8.1f MiB\n", frames, kib / 1024.0);
    }
  }
  std::printf(
      "soak: rss at warm-up end (%d frames) %.1f MiB, peak after %.1f MiB, growth (mean of the"
      " last quarter of samples minus the first quarter after warm-up) %.2f MiB (limit %.1f)\n",
      c.warmup, r.baseline_kib / 1024.0, r.peak_after_kib / 1024.0, r.growth_kib() / 1024.0,
      max_growth_mb);
  std::printf("soak: %.1f s, %.1f fps, latency p50 %.1f ms p99 %.1f ms max %.1f ms\n",
              r.summary.wall_s, r.summary.throughput_fps, r.summary.latency_p50_ms,
              r.summary.latency_p99_ms, r.summary.latency_max_ms);

  // Guards that the labelling does real work. At 320x240 and above the looped approach fires; at
  // smaller sizes the box stays below the (scaled) minimum area, so only the count is printed.
  std::printf("soak: alarm frames %d\n", r.summary.alarm_frames);
  if (c.width >= 320) {
    EXPECT_GT(r.summary.alarm_frames, 0) << "the looped approach must keep firing";
  }
  // Lost, repeated or out-of-order frames, drops and memory growth (soak.hpp, failures()).
  for (const std::string& why : failures(c, r, max_growth_mb)) ADD_FAILURE() << "soak: " << why;
}

}  // namespace
}  // namespace sg::pipeline::soak
