// `plain_loop`: the program a user would write instead of `stereoguard run` on a stereo folder
// (docs/inputs.md), as the whole-process baseline of scripts/bench_process.sh. One frame
// at a time: cv::imread of both PNGs, StereoBM, DIS ultrafast (Stereo-Flow), the labelling, with
// OpenCV's default threads; no pipeline. Prints the frames, alarm frames and the wall time.
#include "sg/pipeline/plain_loop.hpp"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "sg/core/error.hpp"
#include "sg/core/params.hpp"
#include "sg/io/stereo_folder.hpp"

namespace fs = std::filesystem;

namespace {

std::vector<fs::path> pngs(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw sg::core::InputError("missing folder: " + dir.string());
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".png") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

cv::Mat read(const fs::path& path) {
  cv::Mat image = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
  if (image.empty()) throw sg::core::InputError("cannot read image: " + path.string());
  return image;
}

int run(const fs::path& dir, const std::string& mode, const std::string& labelling) {
  const std::vector<fs::path> left = pngs(dir / "left"), right = pngs(dir / "right");
  if (left.empty() || left.size() != right.size())
    throw sg::core::InputError(dir.string() +
                               ": left/ and right/ must hold equal, non-zero "
                               "counts of .png files");
  const auto start = std::chrono::steady_clock::now();
  sg::core::StereoFrame frame;
  frame.left = read(left[0]);
  const sg::core::Camera camera = sg::io::read_camera_yaml(dir / "camera.yaml", frame.left.size());
  sg::core::DetectorParams params;
  params.mode = sg::core::parse_mode(mode);
  if (labelling == "naive") params = sg::pipeline::naive_labelling(params);
  sg::core::throw_if_invalid(sg::core::validate(params, camera), "invalid parameters");
  sg::pipeline::PlainLoop loop(params, camera);

  int alarms = 0;
  for (size_t i = 0; i < left.size(); ++i) {
    if (i > 0) frame.left = read(left[i]);
    frame.right = read(right[i]);
    if (frame.right.size() != frame.left.size())
      throw sg::core::InputError("size mismatch: " + right[i].string());
    frame.index = static_cast<int>(i);
    frame.time_s = static_cast<double>(i) / camera.fps;
    if (loop.process(frame).signal) ++alarms;
  }
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "frames " << left.size() << "  alarm frames " << alarms << "  wall " << wall_s
            << " s  " << left.size() / wall_s << " fps  (mode " << mode << ", labelling "
            << labelling << ", OpenCV threads " << cv::getNumThreads() << ")\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "plain_loop: the sequential OpenCV loop on a stereo folder (whole-process baseline)"};
  std::string dir, mode = "stereo-flow", labelling = "naive";
  app.add_option("--input", dir, "stereo folder (camera.yaml, left/*.png, right/*.png)")
      ->required();
  app.add_option("--mode", mode, "stereo or stereo-flow (default)");
  app.add_option("--labelling", labelling,
                 "naive (default: one frame gap) or full (the detector's default gaps, as run)")
      ->check(CLI::IsMember({"naive", "full"}));
  CLI11_PARSE(app, argc, argv);
  try {
    return run(dir, mode, labelling);
  } catch (const std::exception& e) {
    std::cerr << "plain_loop: " << e.what() << "\n";
    return 2;
  }
}
