// libFuzzer target: PFM disparity (io::read_pfm; Middlebury 2014, SceneFlow GT).
#include "fuzz_input.hpp"
#include "sg/io/stereo_gt.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = sg::fuzz::write_input(data, size, ".pfm");
  sg::fuzz::expect_only_input_errors([&] { (void)sg::io::read_pfm(path); });
  return 0;
}
