// libFuzzer target: KITTI-style 16-bit disparity PNG (io::read_disparity_png).
#include "fuzz_input.hpp"
#include "sg/io/gt_formats.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = sg::fuzz::write_input(data, size, ".png");
  sg::fuzz::expect_only_input_errors([&] { (void)sg::io::read_disparity_png(path); });
  return 0;
}
