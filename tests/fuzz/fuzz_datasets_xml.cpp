// libFuzzer target: OpenCV's Middlebury datasets.xml, read for the GT scale of each scene when
// `eval-stereo` discovers pairs (io::find_stereo_gt_pairs). The fuzzed bytes are DIR/datasets.xml
// next to a scene folder DIR/scene1 holding (empty) im2.png, im6.png and disp2.png.
#include <fstream>

#include "fuzz_input.hpp"
#include "sg/io/stereo_gt.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto xml = sg::fuzz::write_named_input(data, size, "gt/datasets.xml");
  const auto dir = xml.parent_path();
  static const bool scene_made = [&] {
    for (const char* f : {"im2.png", "im6.png", "disp2.png"}) {
      std::filesystem::create_directories(dir / "scene1");
      std::ofstream(dir / "scene1" / f);
    }
    return true;
  }();
  (void)scene_made;
  sg::fuzz::expect_only_input_errors([&] { (void)sg::io::find_stereo_gt_pairs(dir, 0.0); });
  return 0;
}
