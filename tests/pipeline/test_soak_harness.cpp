// The soak harness itself (tests/pipeline/soak.hpp), on a short run: it counts every frame in
// and out, and its memory check sees a leak when there is one.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "soak.hpp"

namespace sg::pipeline::soak {
namespace {

#if defined(__SANITIZE_ADDRESS__)
// ASan holds freed blocks in its quarantine (256 MiB by default), so resident memory grows in any
// run: the memory verdict means nothing there. The frame counts are checked in every build.
constexpr bool kMemoryMeasurable = false;
#else
constexpr bool kMemoryMeasurable = true;
#endif

/// failures() without its memory verdict when memory cannot be measured (ASan).
std::vector<std::string> counted_failures(const Config& c, const Result& r) {
  std::vector<std::string> out;
  for (const std::string& why : failures(c, r, 4.0)) {
    if (kMemoryMeasurable || why.find("memory grew") == std::string::npos) out.push_back(why);
  }
  return out;
}

Config short_config() {
  Config c;
  c.frames = 400;
  c.width = 160;
  c.height = 120;
  c.loop = 8;
  c.warmup = 100;
  c.sample_every = 50;
  c.options.params.mode = core::Mode::kStereoFlow;
  c.options.params.bm.num_disparities = 32;
  c.options.workers = 2;
  c.options.tiles = 2;
  return c;
}

TEST(SoakHarness, CountsEveryFrameInOrder) {
  const Config c = short_config();
  const Result r = run_soak(c);
  EXPECT_EQ(r.frames_in, c.frames);
  EXPECT_EQ(r.frames_out, c.frames);
  EXPECT_EQ(r.out_of_order, 0);
  EXPECT_EQ(r.dropped, 0);
  // Samples: at start, at the warm-up end, then every sample_every frames.
  EXPECT_EQ(r.samples.size(), 1u + c.frames / c.sample_every);
  EXPECT_GT(r.baseline_kib, 0);
  EXPECT_TRUE(counted_failures(c, r).empty());
}

TEST(SoakHarness, SeesALeak) {
  if (!kMemoryMeasurable) GTEST_SKIP() << "resident memory is not measurable under ASan";
  const Config c = short_config();
  // 64 KiB kept per frame, touched so that it is resident: 300 frames after the warm-up leak
  // ~19 MiB; the quarter means of the samples (150..400) are ~200 frames = ~12 MiB apart.
  std::vector<std::unique_ptr<std::vector<char>>> leak;
  const Result r =
      run_soak(c, [&] { leak.push_back(std::make_unique<std::vector<char>>(65536, 1)); });
  EXPECT_GT(r.growth_kib(), 8 * 1024);
  const auto why = failures(c, r, 4.0);
  ASSERT_EQ(why.size(), 1u);
  EXPECT_NE(why[0].find("memory grew"), std::string::npos) << why[0];
}

/// A frame lost from the stream (numbers jump from 149 to 151) fails the soak: every later frame
/// is out of order, and the gap is a dropped frame.
TEST(SoakHarness, SeesALostFrame) {
  Config c = short_config();
  c.tamper = [](core::StereoFrame& f) {
    if (f.index >= 150) ++f.index;
  };
  const Result r = run_soak(c);
  EXPECT_EQ(r.frames_out, c.frames);
  EXPECT_EQ(r.out_of_order, c.frames - 150);
  // The pipeline counts the gap in the indices as a dropped frame too.
  EXPECT_EQ(r.dropped, 1);
  const auto why = counted_failures(c, r);
  ASSERT_EQ(why.size(), 2u);
  EXPECT_NE(why[0].find("out of order"), std::string::npos) << why[0];
  EXPECT_NE(why[1].find("dropped 1"), std::string::npos) << why[1];
}

/// A repeated frame (frame 150 numbered 149) stops the run: the detector refuses it.
TEST(SoakHarness, ARepeatedFrameStopsTheRun) {
  Config c = short_config();
  c.tamper = [](core::StereoFrame& f) {
    if (f.index == 150) f.index = 149;
  };
  EXPECT_THROW(run_soak(c), std::exception);
}

}  // namespace
}  // namespace sg::pipeline::soak
