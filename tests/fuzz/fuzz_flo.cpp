// libFuzzer target: Middlebury .flo optical flow (io::read_flo).
#include "fuzz_input.hpp"
#include "sg/io/gt_formats.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = sg::fuzz::write_input(data, size, ".flo");
  sg::fuzz::expect_only_input_errors([&] { (void)sg::io::read_flo(path); });
  return 0;
}
