// libFuzzer target: KITTI calib_cam_to_cam.txt (io::read_calibration of a .txt: cameras 0/1 and
// 2/3), and the camera it gives validated as open_kitti does.
#include "fuzz_input.hpp"
#include "sg/core/camera.hpp"
#include "sg/io/calibration.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = sg::fuzz::write_input(data, size, ".txt");
  for (const bool color : {false, true}) {
    sg::fuzz::expect_only_input_errors([&] {
      const sg::io::Calibration c = sg::io::read_calibration(path, color);
      if (c.rectified) (void)sg::core::validate(*c.rectified);
    });
  }
  return 0;
}
