// stereoguard as a library: run the obstacle pipeline on a stereo folder (camera.yaml, left/,
// right/) and print one JSON event per frame on stdout, the run's summary on stderr.
//   run_folder DIR [stereo|stereo-flow]
#include <iostream>

#include "sg/core/error.hpp"
#include "sg/io/events.hpp"
#include "sg/io/stereo_folder.hpp"
#include "sg/pipeline/runner.hpp"

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::cerr << "usage: run_folder STEREO_FOLDER [stereo|stereo-flow]\n";
    return 2;
  }
  try {
    sg::io::FolderSource source(argv[1]);

    sg::pipeline::RunOptions options;  // Stereo mode unless argv[2] names one (run: stereo-flow)
    if (argc == 3) options.params.mode = sg::core::parse_mode(argv[2]);
    options.workers = 2;  // two frames' stereo matching at once

    const sg::pipeline::RunSummary summary = sg::pipeline::run(
        source, options, [](const sg::core::StereoFrame&, const sg::core::Detection& d) {
          // Called in frame order. Fields: docs/outputs.md, or include/sg/core/detection.hpp.
          std::cout << sg::io::detection_to_json(d, /*timing=*/false).dump() << "\n";
        });
    std::cerr << summary.text();
  } catch (const sg::core::InputError& e) {
    std::cerr << "run_folder: error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
