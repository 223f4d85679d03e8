// libFuzzer target: KITTI raw image_0X/timestamps.txt (io::read_kitti_times), and the frame rate
// taken from it (io::fps_from_times), as open_kitti does.
#include "fuzz_input.hpp"
#include "sg/io/sources.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = sg::fuzz::write_input(data, size, ".txt");
  sg::fuzz::expect_only_input_errors(
      [&] { (void)sg::io::fps_from_times(sg::io::read_kitti_times(path)); });
  return 0;
}
