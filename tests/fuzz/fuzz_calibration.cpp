// libFuzzer target: a `--calib` file told apart by content (io::read_calibration: stereoguard
// camera.yaml, or an OpenCV YAML/XML/JSON stereo calibration), then the rectification maps built
// from a raw calibration for 64x48 frames (io::make_rectification), as the CLI does.
#include "fuzz_input.hpp"
#include "sg/io/calibration.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = sg::fuzz::write_input(data, size, ".yml");
  sg::fuzz::expect_only_input_errors([&] {
    const sg::io::Calibration c = sg::io::read_calibration(path);
    if (c.stereo) (void)sg::io::make_rectification(*c.stereo, cv::Size(64, 48), path.string());
  });
  return 0;
}
