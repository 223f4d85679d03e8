// Decoding one 8-bit gray PNG file from disk, one thread: cv::imread as the plain loop calls it
// (`imread_grayscale`), read_gray's reference (`opencv`, cv::imread unchanged + conversion) and
// read_gray itself (`fast`: libdeflate and our unfiltering). The file: $SG_BENCH_PNG when set,
// else the first EuRoC frame (752x480) when ../shared is present, else a 752x480 blurred-noise
// image written to /tmp.
// Counter: megapixels per second.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sg/io/gray_image.hpp"

namespace {

namespace fs = std::filesystem;

fs::path test_file() {
  static const fs::path path = [] {
    if (const char* chosen = std::getenv("SG_BENCH_PNG")) return fs::path(chosen);
    const fs::path euroc = fs::path(SG_SHARED_DIR) / "data" / "euroc_v1_01_micro" / "mav0" /
                           "cam0" / "data" / "1403715273262142976.png";
    if (fs::is_regular_file(euroc)) return euroc;
    cv::Mat noise(480, 752, CV_8UC1), image;
    cv::RNG(3).fill(noise, cv::RNG::UNIFORM, 0, 256);
    cv::GaussianBlur(noise, image, cv::Size(0, 0), 1.5);
    const fs::path out = fs::temp_directory_path() / "sg_bench_decode.png";
    cv::imwrite(out.string(), image);
    return out;
  }();
  return path;
}

template <typename Read>
void run(benchmark::State& state, Read read) {
  const fs::path path = test_file();
  cv::Mat image;
  for (auto _ : state) {
    image = read(path);
    benchmark::DoNotOptimize(image.data);
  }
  state.counters["Mpx/s"] = benchmark::Counter(
      static_cast<double>(image.total()) * static_cast<double>(state.iterations()) / 1e6,
      benchmark::Counter::kIsRate);
  state.SetLabel(path.filename().string());
}

void BM_imread_grayscale(benchmark::State& s) {
  run(s, [](const fs::path& p) { return cv::imread(p.string(), cv::IMREAD_GRAYSCALE); });
}
void BM_opencv(benchmark::State& s) { run(s, sg::io::read_gray_opencv); }
void BM_fast(benchmark::State& s) { run(s, sg::io::read_gray); }

BENCHMARK(BM_imread_grayscale)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_opencv)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_fast)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  cv::setNumThreads(1);
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
