// libFuzzer target: camera.yaml of a stereo folder (io::read_camera_yaml).
#include <opencv2/core.hpp>

#include "fuzz_input.hpp"
#include "sg/io/stereo_folder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = sg::fuzz::write_input(data, size, ".yaml");
  sg::fuzz::expect_only_input_errors([&] { (void)sg::io::read_camera_yaml(path, {640, 480}); });
  return 0;
}
