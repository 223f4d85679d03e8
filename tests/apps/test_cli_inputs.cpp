// Runs the stereoguard binary on real-input kinds (videos, side-by-side, KITTI, EuRoC, image globs
// with a calibration from `calibrate`) and on every bad input of issue 7: one clear line, exit
// status 2, events already written still valid JSON lines.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "../io/calibration_text.hpp"

namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

class Inputs : public ::testing::Test {
 protected:
  struct Output {
    int status = -1;
    std::string out, err;
  };

  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) / ("sg_inputs_" + std::string(info->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// Runs a shell command line in the test folder; stdout and stderr captured.
  Output shell(const std::string& line) {
    const std::string cmd = "cd '" + dir_.string() + "' && " + line + " >stdout.txt 2>stderr.txt";
    const int raw = std::system(cmd.c_str());
    return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, read_text(dir_ / "stdout.txt"),
            read_text(dir_ / "stderr.txt")};
  }
  Output sg(const std::string& args) { return shell("'" SG_STEREOGUARD_BIN "' " + args); }

  /// The test scenario at 25 Hz (frame times i * 0.04 s are exact in decimal, as KITTI writes them)
  /// rendered into dir/fold; its events (no timing) in dir/fold.jsonl.
  void make_folder(int frames = 12) {
    std::ofstream(dir_ / "small.yaml")
        << "name: small\nframes: " << frames << "\n"
        << "camera: {width: 321, height: 241, focal_px: 250, cx: 160, cy: 120, fps: 25}\n"
        << "obstacles:\n  - {id: 1, size_m: [1.0, 1.5, 0.5], position_m: [0, 0.45, 4.0], "
           "velocity_mps: [0, 0, -3]}\n";
    ASSERT_EQ(sg("simulate --scenario small.yaml --out fold").status, 0);
    const Output r = sg("run --input fold --events fold.jsonl --no-timing --quiet");
    ASSERT_EQ(r.status, 0) << r.err;
  }

  void require_ffmpeg() {
    if (std::system("command -v ffmpeg >/dev/null 2>&1") != 0) GTEST_SKIP() << "no ffmpeg";
  }
  /// Lossless gray FFV1 in MKV from the PNGs of `pattern` (e.g. fold/left/%06d.png).
  void encode(const std::string& pattern, const std::string& out, const std::string& extra = "") {
    const Output r = shell("ffmpeg -loglevel error -y -framerate 25 -i " + pattern + " " + extra +
                           " -c:v ffv1 -pix_fmt gray " + out);
    ASSERT_EQ(r.status, 0) << r.err;
  }

  /// Expects exit status 2 and exactly one line on stderr that mentions `needle`.
  void expect_user_error(const Output& r, const std::string& needle) {
    EXPECT_EQ(r.status, 2) << r.err;
    ASSERT_FALSE(r.err.empty());
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "more than one line: " << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
  }

  /// Number of lines of an events file, each checked to be a complete JSON object.
  int valid_event_lines(const fs::path& file) {
    std::ifstream in(dir_ / file);
    std::string line;
    int n = 0;
    while (std::getline(in, line)) {
      EXPECT_TRUE(nlohmann::json::accept(line)) << "line " << n << ": " << line;
      ++n;
    }
    return n;
  }

  void expect_same_events_as_folder(const std::string& file) {
    const std::string folder = read_text(dir_ / "fold.jsonl");
    ASSERT_FALSE(folder.empty());
    EXPECT_NE(folder.find("\"signal\":true"), std::string::npos) << "the scenario must warn";
    EXPECT_EQ(read_text(dir_ / file), folder);
  }

  fs::path dir_;
};

TEST_F(Inputs, AFolderThatSimulateWroteIsScoredForItsScenariosPlatform) {
  // The car's contact plane lies 2.0 m ahead, the robot's 0.5 m: an obstacle 3.5 m away closing at
  // 3 m/s is due at once for the car and not yet for the robot.
  std::ofstream(dir_ / "car.yaml")
      << "name: small-car\nframes: 12\nplatform: car\n"
      << "camera: {width: 321, height: 241, focal_px: 250, cx: 160, cy: 120, fps: 25}\n"
      << "obstacles:\n  - {id: 1, size_m: [1.0, 1.5, 0.5], position_m: [0, 0.45, 3.5], "
         "velocity_mps: [0, 0, -3]}\n";
  ASSERT_EQ(sg("simulate --scenario car.yaml --out fold").status, 0);
  for (const char* run : {"--events own.jsonl", "--events car.jsonl --platform car",
                          "--events robot.jsonl --platform robot"}) {
    const Output r = sg(std::string("run --input fold --no-timing --quiet ") + run);
    ASSERT_EQ(r.status, 0) << r.err;
  }
  const std::string own = read_text(dir_ / "own.jsonl");
  ASSERT_FALSE(own.empty());
  EXPECT_EQ(own, read_text(dir_ / "car.jsonl"));
  EXPECT_NE(own, read_text(dir_ / "robot.jsonl"));
  // A scenario.yaml that does not load is a clear error, not the robot's figures.
  std::ofstream(dir_ / "fold" / "scenario.yaml") << "platform: boat\n";
  expect_user_error(sg("run --input fold --quiet"), "boat");
}

TEST_F(Inputs, TwoLosslessVideosGiveTheEventsOfTheFolder) {
  require_ffmpeg();
  make_folder();
  encode("fold/left/%06d.png", "l.mkv");
  encode("fold/right/%06d.png", "r.mkv");
  const Output r =
      sg("run --left l.mkv --right r.mkv --calib fold/camera.yaml --events v.jsonl "
         "--no-timing --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  expect_same_events_as_folder("v.jsonl");
  // The same input from the config file's input: section.
  std::ofstream(dir_ / "c.yaml") << "input: {left: l.mkv, right: r.mkv, calib: fold/camera.yaml}\n";
  ASSERT_EQ(sg("run --config c.yaml --events c.jsonl --no-timing --quiet").status, 0);
  expect_same_events_as_folder("c.jsonl");
  std::ofstream(dir_ / "bad.yaml") << "input: {left: l.mkv, rigth: r.mkv}\n";
  expect_user_error(sg("run --config bad.yaml"), "input.rigth is not a known setting");
}

TEST_F(Inputs, SideBySideLosslessVideoGivesTheEventsOfTheFolder) {
  require_ffmpeg();
  make_folder();
  encode("fold/left/%06d.png", "sbs.mkv",
         "-framerate 25 -i fold/right/%06d.png -filter_complex hstack");
  const Output r =
      sg("run --sbs sbs.mkv --calib fold/camera.yaml --events s.jsonl --no-timing --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  expect_same_events_as_folder("s.jsonl");
}

TEST_F(Inputs, ImageFoldersWithCameraFlagsGiveTheEventsOfTheFolder) {
  make_folder();
  const Output r =
      sg("run --left fold/left --right 'fold/right/*.png' --focal 250 --baseline 0.12 "
         "--cx 160 --cy 120 --input-fps 25 --events g.jsonl --no-timing --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  expect_same_events_as_folder("g.jsonl");
}

TEST_F(Inputs, KittiLayoutGivesTheEventsOfTheFolder) {
  make_folder();
  const fs::path drive = dir_ / "2011_09_26" / "2011_09_26_drive_0001_sync";
  for (const char* cam : {"image_00", "image_01"}) {
    fs::create_directories(drive / cam / "data");
    std::ofstream stamps(drive / cam / "timestamps.txt");
    for (int i = 0; i < 12; ++i) {
      char name[32], stamp[64];
      std::snprintf(name, sizeof name, "%010d.png", i);
      std::snprintf(stamp, sizeof stamp, "2011-09-26 13:02:%012.9f", 25.0 + i * 0.04);
      stamps << stamp << "\n";
      char src[32];
      std::snprintf(src, sizeof src, "%06d.png", i);
      fs::copy_file(dir_ / "fold" / (cam == std::string("image_00") ? "left" : "right") / src,
                    drive / cam / "data" / name);
    }
  }
  // KITTI's calib file sits beside the drive folders; P_rect_01(0,3) = -f * B.
  std::ofstream(dir_ / "2011_09_26" / "calib_cam_to_cam.txt")
      << "calib_time: 09-Jan-2012 13:57:47\ncorner_dist: 9.950000e-02\n"
      << "S_rect_00: 321 241\nP_rect_00: 250 0 160 0 0 250 120 0 0 0 1 0\n"
      << "S_rect_01: 321 241\nP_rect_01: 250 0 160 -30 0 250 120 0 0 0 1 0\n";
  const Output r =
      sg("run --kitti 2011_09_26/2011_09_26_drive_0001_sync --events k.jsonl "
         "--no-timing --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  expect_same_events_as_folder("k.jsonl");
  // The colour cameras are not there: say so.
  expect_user_error(sg("run --kitti 2011_09_26/2011_09_26_drive_0001_sync --kitti-color"),
                    "image_02");
}

TEST_F(Inputs, CalibrateOnTheOpencvChessboardsThenRunOnThem) {
  const fs::path data = "/usr/share/doc/opencv-doc/examples/data";
  if (!fs::exists(data / "left01.jpg")) GTEST_SKIP() << "opencv-doc is not installed";
  const std::string left = "'" + (data / "left??.jpg").string() + "'";
  const std::string right = "'" + (data / "right??.jpg").string() + "'";
  const Output c = sg("calibrate --left " + left + " --right " + right +
                      " --board 9x6 --square 0.025 --out c.yaml");
  ASSERT_EQ(c.status, 0) << c.err;
  const size_t at = c.out.find("RMS error");
  ASSERT_NE(at, std::string::npos) << c.out;
  const double rms = std::stod(c.out.substr(at + 10));
  EXPECT_GT(rms, 0.0);
  EXPECT_LT(rms, 1.0);
  EXPECT_NE(c.out.find("pairs used        13"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("epipolar error"), std::string::npos) << c.out;
  const Output r = sg("run --left " + left + " --right " + right +
                      " --calib c.yaml --input-fps 1 --events e.jsonl --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(valid_event_lines("e.jsonl"), 13);
  // A board that is not in the images.
  expect_user_error(
      sg("calibrate --left " + left + " --right " + right + " --board 7x5 --out d.yaml"),
      "board was found in only 0 image pairs");
}

TEST_F(Inputs, EurocRunWritesOneEventPerPair) {
  const fs::path euroc = fs::path(SG_SHARED_DIR) / "data" / "euroc_v1_01_micro";
  if (!fs::is_directory(euroc)) GTEST_SKIP() << "no EuRoC clip at " << euroc;
  const Output r = sg("run --euroc '" + euroc.string() + "' --events e.jsonl --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(valid_event_lines("e.jsonl"), 95);
  EXPECT_NE(r.out.find("752x480, 95 frames"), std::string::npos) << r.out;
  // Stamps from data.csv: the last pair is 4.70 s after the first.
  std::ifstream in(dir_ / "e.jsonl");
  std::string line, last;
  while (std::getline(in, line)) last = line;
  EXPECT_NEAR(nlohmann::json::parse(last)["time_s"].get<double>(), 4.70, 0.001);
}

TEST_F(Inputs, BenchOnARealInputUsesItsFramesAndResolution) {
  make_folder(6);
  const Output r =
      sg("bench --left fold/left --right fold/right --calib fold/camera.yaml --modes "
         "stereo --workers 1,2 --tiles 1 --frames 14 --pace 2 --capacity-runs 1 --csv b.csv");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("input fold/left + fold/right"), std::string::npos) << r.out;
  std::ifstream csv(dir_ / "b.csv");
  std::vector<std::string> rows;
  for (std::string line; std::getline(csv, line);) rows.push_back(line);
  ASSERT_EQ(rows.size(), 6u) << r.out;  // header, baseline, opencv-mt, W 1, W 2, paced
  for (size_t i = 1; i < rows.size(); ++i) {
    EXPECT_NE(rows[i].find(",stereo,321,241,"), std::string::npos) << rows[i];
  }
  // same_detections of the W 1 and W 2 rows, found by its header name.
  auto field = [](const std::string& row, size_t index) {
    std::stringstream s(row);
    std::string cell;
    for (size_t i = 0; i <= index && std::getline(s, cell, ','); ++i) {
    }
    return cell;
  };
  std::vector<std::string> header;
  std::stringstream hs(rows[0]);
  for (std::string cell; std::getline(hs, cell, ',');) header.push_back(cell);
  const auto same = std::find(header.begin(), header.end(), "same_detections");
  ASSERT_NE(same, header.end()) << rows[0];
  const size_t column = static_cast<size_t>(same - header.begin());
  EXPECT_EQ(field(rows[3], column), "yes") << rows[3];
  EXPECT_EQ(field(rows[4], column), "yes") << rows[4];
}

// ---------------------------------------------------------------------------------------------
// Bad input

TEST_F(Inputs, UnreadableVideo) {
  std::ofstream(dir_ / "junk.mkv") << "not a video at all";
  std::ofstream(dir_ / "junk2.mkv") << "not a video at all";
  expect_user_error(sg("run --left junk.mkv --right junk2.mkv --focal 500 --baseline 0.1"),
                    "cannot read video (corrupt or not a video): junk.mkv");
  expect_user_error(sg("run --sbs missing.mkv --focal 500 --baseline 0.1"),
                    "video not found: missing.mkv");
}

TEST_F(Inputs, TruncatedVideoStopsWithAnErrorAndValidEvents) {
  require_ffmpeg();
  make_folder();
  encode("fold/left/%06d.png", "l.mkv");
  encode("fold/right/%06d.png", "r.mkv");
  const auto full = fs::file_size(dir_ / "l.mkv");
  fs::resize_file(dir_ / "l.mkv", full / 2);
  const Output r =
      sg("run --left l.mkv --right r.mkv --calib fold/camera.yaml --events t.jsonl "
         "--quiet");
  expect_user_error(r, "video l.mkv ends after");
  const int lines = valid_event_lines("t.jsonl");
  EXPECT_GT(lines, 0);
  EXPECT_LT(lines, 12);
}

TEST_F(Inputs, VideosOfDifferentSizes) {
  require_ffmpeg();
  make_folder(3);
  encode("fold/left/%06d.png", "l.mkv");
  encode("fold/right/%06d.png", "r.mkv", "-vf scale=320:240");
  expect_user_error(sg("run --left l.mkv --right r.mkv --calib fold/camera.yaml"),
                    "size mismatch: r.mkv is 320x240, l.mkv is 321x241");
}

TEST_F(Inputs, VideosOfDifferentLengthsStopAtTheShorterWithOneWarning) {
  require_ffmpeg();
  make_folder(8);
  encode("fold/left/%06d.png", "l.mkv");
  encode("fold/right/%06d.png", "r.mkv", "-frames:v 5");
  const Output r =
      sg("run --left l.mkv --right r.mkv --calib fold/camera.yaml --events e.jsonl "
         "--quiet");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not one line: " << r.err;
  EXPECT_NE(r.err.find("stereoguard: warning: r.mkv ended after 5 frames"), std::string::npos)
      << r.err;
  EXPECT_EQ(valid_event_lines("e.jsonl"), 5);
}

TEST_F(Inputs, ImageFoldersOfDifferentCountsStopAtTheShorterWithOneWarning) {
  make_folder(6);
  fs::remove(dir_ / "fold" / "right" / "000005.png");
  const Output r =
      sg("run --left fold/left --right fold/right --calib fold/camera.yaml "
         "--events e.jsonl --quiet");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not one line: " << r.err;
  EXPECT_NE(r.err.find("has 6 frames, fold/right has 5"), std::string::npos) << r.err;
  EXPECT_EQ(valid_event_lines("e.jsonl"), 5);
}

TEST_F(Inputs, CalibrationWithAMissingFieldANanOrASingularMatrix) {
  make_folder(2);
  const std::string input = "run --left fold/left --right fold/right --calib c.yaml";
  sg::io::testing_util::write_calibration_text(dir_ / "c.yaml", "");
  expect_user_error(sg(input), "c.yaml: missing field 'M1'");
  sg::io::testing_util::write_calibration_text(dir_ / "c.yaml",
                                               "250, 0, .nan, 0, 250, 120, 0, 0, 1");
  expect_user_error(sg(input), "calib.M1: has a value that is not finite");
  sg::io::testing_util::write_calibration_text(dir_ / "c.yaml",
                                               "250, 0, 160, 250, 0, 120, 0, 0, 1");
  expect_user_error(sg(input), "calib.M1: not an invertible camera matrix");
  sg::io::testing_util::write_calibration_text(dir_ / "c.yaml",
                                               "250, 0, 160, 0, 250, 120, 0, 0, 1");
  EXPECT_EQ(sg(input + " --input-fps 25 --quiet").status, 0);
  std::ofstream(dir_ / "calib_cam_to_cam.txt") << "P_rect_00: 250 0 160 0 0 250 nan 0 0 0 1 0\n";
  expect_user_error(sg("run --left fold/left --right fold/right --calib calib_cam_to_cam.txt"),
                    "P_rect_00' has a value that is not finite");
}

TEST_F(Inputs, CameraThatDoesNotExist) {
  expect_user_error(sg("run --camera 93,94 --focal 500 --baseline 0.1"), "camera 93 not found");
  expect_user_error(sg("run --camera 93 --sbs --focal 500 --baseline 0.1"), "camera 93 not found");
  expect_user_error(sg("run --camera 93 --focal 500 --baseline 0.1"), "one index with --sbs");
}

TEST_F(Inputs, EmptyImageFolder) {
  fs::create_directories(dir_ / "l");
  fs::create_directories(dir_ / "r");
  expect_user_error(sg("run --left l --right r --focal 500 --baseline 0.1"),
                    "no images in folder l");
  expect_user_error(sg("run --left 'l/*.png' --right 'r/*.png' --focal 500 --baseline 0.1"),
                    "no images match l/*.png");
}

TEST_F(Inputs, FrameSizeChangingMidSequenceKeepsEventsValid) {
  make_folder(6);
  const cv::Mat small = cv::imread((dir_ / "fold" / "left" / "000004.png").string());
  cv::Mat resized;
  cv::resize(small, resized, cv::Size(300, 200));
  cv::imwrite((dir_ / "fold" / "left" / "000004.png").string(), resized);
  const Output r =
      sg("run --left fold/left --right fold/right --calib fold/camera.yaml "
         "--events e.jsonl --quiet");
  expect_user_error(r,
                    "size mismatch: fold/left/000004.png is 300x200, the first frame is 321x241");
  const int lines = valid_event_lines("e.jsonl");
  EXPECT_GE(lines, 1);
  EXPECT_LE(lines, 4);
}

TEST_F(Inputs, PhysicallyImpossibleCameraValues) {
  make_folder(2);
  const std::string input = "run --left fold/left --right fold/right ";
  const std::pair<const char*, const char*> cases[] = {
      {"--focal 250 --baseline 0.12 --input-fps 0", "camera.fps=0"},
      {"--focal 250 --baseline 0.12 --input-fps -30", "camera.fps=-30"},
      {"--focal 250 --baseline 0.12 --input-fps nan", "camera.fps=nan"},
      {"--focal 250 --baseline 0.12 --input-fps inf", "camera.fps=inf"},
      {"--focal 250 --baseline 0.12 --input-fps 1e9", "camera.fps=1e+09"},
      {"--focal 250 --baseline 0.12 --input-fps 25 --cx nan", "--cx=nan"},
      {"--input-fps 25 --focal 1e9 --baseline 0.12", "camera.focal_px=1e+09"},
      {"--focal nan --baseline 0.12 --input-fps 25", "camera.focal_px=nan"},
      {"--focal -250 --baseline 0.12 --input-fps 25", "camera.focal_px=-250"},
      {"--focal inf --baseline 0.12 --input-fps 25", "camera.focal_px=inf"},
      {"--focal 250 --baseline 0 --input-fps 25", "camera.baseline_m=0"},
      {"--focal 250 --baseline -0.1 --input-fps 25", "camera.baseline_m=-0.1"},
      {"--focal 250 --baseline nan --input-fps 25", "camera.baseline_m=nan"},
  };
  for (const auto& [flags, needle] : cases) {
    SCOPED_TRACE(flags);
    expect_user_error(sg(input + flags), needle);
  }
}

TEST_F(Inputs, OneInputAtATimeAndEvalNeedsGroundTruth) {
  make_folder(2);
  expect_user_error(
      sg("run --input fold --left fold/left --right fold/right --focal 1 --baseline 1"),
      "give one input");
  expect_user_error(sg("run --left fold/left --focal 250 --baseline 0.1"),
                    "--left and --right go together");
  expect_user_error(sg("eval --left fold/left --right fold/right --calib fold/camera.yaml"),
                    "has no ground truth");
}

}  // namespace
