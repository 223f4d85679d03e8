// Stereo matcher kernels, one thread, on a synthetic textured scene: OpenCV StereoBM (`bm`),
// OpenCV StereoSGBM (`sgbm`) and our SIMD matcher (`fast`, SAD and census), at 640x480 and
// 1242x375 with 64 and 128 disparities. Counter: megapixels per second.
#include <benchmark/benchmark.h>

#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "sg/core/params.hpp"
#include "sg/vision/stereo_bm.hpp"
#include "sg/vision/stereo_fast.hpp"
#include "sg/vision/stereo_sgbm.hpp"

namespace {

using sg::core::BmParams;
using sg::core::MatchCost;
using sg::core::Matcher;

/// A textured scene: background at disparity 10, a box at 40, right image the left resampled.
struct Pair {
  cv::Mat left, right;
};

Pair make_pair(int width, int height) {
  cv::RNG rng(42);
  cv::Mat noise(height, width + 64, CV_8U);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::Mat tex;
  cv::GaussianBlur(noise, tex, cv::Size(0, 0), 1.2);
  cv::normalize(tex, tex, 0, 255, cv::NORM_MINMAX);
  cv::Mat map_x(height, width, CV_32F), map_y(height, width, CV_32F);
  const cv::Rect box(width / 4, height / 3, width / 3, height / 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      map_x.at<float>(y, x) = static_cast<float>(x) + (box.contains({x, y}) ? 40.0f : 10.0f);
      map_y.at<float>(y, x) = static_cast<float>(y);
    }
  Pair p;
  p.left = tex(cv::Rect(0, 0, width, height)).clone();
  cv::remap(tex, p.right, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return p;
}

void run(benchmark::State& state, Matcher matcher, MatchCost cost) {
  cv::setNumThreads(1);  // one thread: the kernel itself, as DESIGN 8's reference figures
  const int width = static_cast<int>(state.range(0)), height = static_cast<int>(state.range(1));
  const Pair pair = make_pair(width, height);
  BmParams p;
  p.matcher = matcher;
  p.cost = cost;
  p.num_disparities = static_cast<int>(state.range(2));
  p.block_size = static_cast<int>(state.range(3));
  cv::Mat disp(pair.left.size(), CV_32F);
  for (auto _ : state) {
    switch (matcher) {
      case Matcher::kBm:
        sg::vision::match_bm_rows(pair.left, pair.right, p, disp, cv::Range::all());
        break;
      case Matcher::kSgbm:
        sg::vision::match_sgbm_rows(pair.left, pair.right, p, disp, cv::Range::all());
        break;
      case Matcher::kFast:
        sg::vision::match_fast_rows(pair.left, pair.right, p, disp, cv::Range::all());
        break;
      case Matcher::kLongSeq:  // not registered: bench's pipeline rows measure it (--matcher)
        state.SkipWithError("longseq has no row kernel here");
        return;
    }
    benchmark::DoNotOptimize(disp.data);
  }
  state.counters["Mpx/s"] = benchmark::Counter(static_cast<double>(width) * height * 1e-6,
                                               benchmark::Counter::kIsIterationInvariantRate);
  if (matcher == Matcher::kFast) state.SetLabel(sg::vision::fast_matcher_target());
}

void sizes(benchmark::internal::Benchmark* b) {
  for (int nd : {64, 128}) {
    b->Args({640, 480, nd, 11});
    b->Args({1242, 375, nd, 11});
  }
  b->ArgNames({"w", "h", "nd", "block"});
  b->Unit(benchmark::kMillisecond);
  b->UseRealTime();
}

void BM_bm(benchmark::State& s) { run(s, Matcher::kBm, MatchCost::kSad); }
void BM_fast_sad(benchmark::State& s) { run(s, Matcher::kFast, MatchCost::kSad); }
void BM_fast_census(benchmark::State& s) { run(s, Matcher::kFast, MatchCost::kCensus); }
void BM_sgbm(benchmark::State& s) { run(s, Matcher::kSgbm, MatchCost::kSad); }

BENCHMARK(BM_bm)->Apply(sizes);
BENCHMARK(BM_fast_sad)->Apply(sizes);
BENCHMARK(BM_fast_census)->Apply(sizes);
BENCHMARK(BM_sgbm)->Apply(sizes);

}  // namespace

BENCHMARK_MAIN();
