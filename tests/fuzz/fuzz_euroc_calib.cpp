// libFuzzer target: EuRoC cam0/sensor.yaml + cam1/sensor.yaml (io::read_euroc_calibration), then
// the rectification maps for frames of the stated resolution when small, as open_euroc does. The
// input is split at the first line "%%%" into the left and right file (no such line: both files
// are the input).
#include <algorithm>
#include <string_view>

#include "fuzz_input.hpp"
#include "sg/io/calibration.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const std::size_t cut = text.find("\n%%%\n");
  const std::size_t left_size = cut == std::string_view::npos ? size : cut + 1;
  const std::size_t right_at = cut == std::string_view::npos ? 0 : cut + 5;
  const auto left = sg::fuzz::write_named_input(data, left_size, "cam0/sensor.yaml");
  const auto right =
      sg::fuzz::write_named_input(data + right_at, size - right_at, "cam1/sensor.yaml");
  sg::fuzz::expect_only_input_errors([&] {
    const sg::io::StereoCalibration c = sg::io::read_euroc_calibration(left, right);
    const cv::Size s = c.image_size;
    if (s.width <= 128 && s.height <= 128) (void)sg::io::make_rectification(c, s, "fuzz");
  });
  return 0;
}
