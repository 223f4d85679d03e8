// libFuzzer target: GT disparity PNG as `eval-stereo` reads it (io::read_stereo_gt: 16-bit KITTI
// or 8-bit Middlebury 2001-2006 with a scale). The first byte picks the scale (0 = not given).
#include "fuzz_input.hpp"
#include "sg/io/stereo_gt.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const double scale = data[0] % 9;  // 0 (unknown), 1 .. 8
  const auto path = sg::fuzz::write_input(data + 1, size - 1, ".png");
  sg::fuzz::expect_only_input_errors([&] { (void)sg::io::read_stereo_gt(path, scale); });
  return 0;
}
