// `stereoguard calibrate`: stereo calibration from chessboard pairs, written as OpenCV YAML that
// `run --calib` reads.
#include <iomanip>
#include <iostream>

#include "commands.hpp"
#include "options.hpp"
#include "sg/core/error.hpp"
#include "sg/io/calibration.hpp"
#include "sg/io/sources.hpp"

namespace sg::apps {
namespace {

struct CalibrateArgs {
  std::string left, right, board = "9x6", out;
  double square_m = 0.025;
};

void calibrate_main(const CalibrateArgs& a) {
  io::ChessboardParams params;
  params.board = parse_size(a.board, "board", "9x6 (inner corners)");
  params.square_m = a.square_m;
  core::throw_if_invalid(io::validate(params), "invalid calibrate options");
  const auto left = io::list_images(a.left), right = io::list_images(a.right);
  const io::ChessboardResult r = io::calibrate_chessboard(left, right, params);
  io::write_opencv_calibration(a.out, r.calib);
  const double f = r.calib.P1.at<double>(0, 0);
  std::cout << std::fixed << std::setprecision(3) << "calibrate: " << left.size()
            << " pairs, board " << a.board << ", square " << a.square_m << " m\n"
            << "pairs used        " << r.pairs_used << "\n";
  for (const auto& s : r.skipped) std::cout << "  no board in      " << s << "\n";
  std::cout << "RMS error         " << r.rms_px << " px\n"
            << "epipolar error    " << r.epipolar_px << " px\n"
            << "rectified camera  focal " << f << " px, baseline "
            << -r.calib.P2.at<double>(0, 3) / f << " m, cx " << r.calib.P1.at<double>(0, 2)
            << ", cy " << r.calib.P1.at<double>(1, 2) << "\n"
            << "wrote             " << a.out << "\n";
}

}  // namespace

void add_calibrate_command(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "stereo calibration from chessboard image pairs (writes OpenCV YAML for --calib)");
  cmd->add_option("--left", args->left, "left images: folder or glob pattern ('data/left*.jpg')")
      ->required();
  cmd->add_option("--right", args->right, "right images: folder or glob pattern")->required();
  cmd->add_option("--board", args->board, "inner corners per row x per column (default 9x6)");
  cmd->add_option("--square", args->square_m, "side of one square, m (default 0.025)");
  cmd->add_option("--out", args->out, "calibration file to write (.yaml or .xml)")->required();
  cmd->callback([args] { calibrate_main(*args); });
}

}  // namespace sg::apps
