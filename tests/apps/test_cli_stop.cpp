// `run` stopped by SIGINT or SIGTERM while it runs: exit status 128 + signal, complete outputs
// (a video that plays with one frame per detection, one valid event line and one CSV row per
// detection, a summary saying "interrupted"); and `--show` without a display is a user error.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/videoio.hpp>
#include <string>

#include "cli_run.hpp"
#include "cli_spawn.hpp"

namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

class CliStop : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "_" + info->name();
    for (char& c : name)
      if (c == '/') c = '_';
    dir_ = fs::path(::testing::TempDir()) / ("sg_stop_" + name);
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

/// Frames of a video, read one by one (the container's frame count is only an estimate).
int video_frames(const fs::path& p) {
  cv::VideoCapture in(p.string());
  if (!in.isOpened()) return -1;
  int n = 0;
  for (cv::Mat f; in.read(f) && !f.empty();) ++n;
  return n;
}

class StopSignal : public CliStop, public ::testing::WithParamInterface<int> {};

TEST_P(StopSignal, EndsWithCompleteOutputsAndTheSignalsStatus) {
  const int sig = GetParam();
  // 150 frames paced at 10 Hz: 15 s of camera time, signalled a few frames in.
  const pid_t pid = sg::test::spawn(
      {SG_STEREOGUARD_BIN, "run", "--scenario", "crossing", "--fps", "10", "--quiet", "--events",
       "events.jsonl", "--csv", "metrics.csv", "--overlay", "overlay.mp4", "--summary",
       "summary.json"},
      dir_, dir_ / "stdout.txt", dir_ / "stderr.txt");
  ASSERT_GT(pid, 0);
  ASSERT_TRUE(sg::test::wait_lines(dir_ / "events.jsonl", 3, pid, 300s))
      << sg::test::slurp(dir_ / "stderr.txt");
  ASSERT_EQ(kill(pid, sig), 0);
  const std::optional<int> status = sg::test::wait_exit(pid, 300s);
  ASSERT_TRUE(status) << "still running 300 s after the signal";
  EXPECT_EQ(*status, 128 + sig) << sg::test::slurp(dir_ / "stderr.txt");

  const nlohmann::json summary = nlohmann::json::parse(sg::test::slurp(dir_ / "summary.json"));
  EXPECT_TRUE(summary.at("interrupted").get<bool>());
  const int frames = summary.at("frames").get<int>();
  EXPECT_GE(frames, 3);
  EXPECT_LT(frames, 150);

  std::ifstream events(dir_ / "events.jsonl");
  int lines = 0, previous = -1;
  for (std::string line; std::getline(events, line); ++lines) {
    const nlohmann::json e = nlohmann::json::parse(line);  // throws on a cut line
    EXPECT_GT(e.at("frame").get<int>(), previous);
    previous = e.at("frame").get<int>();
  }
  EXPECT_EQ(lines, frames);
  EXPECT_EQ(sg::test::complete_lines(dir_ / "metrics.csv"), frames + 1);  // header + rows
  // The video was finalised (it plays) and renamed from its partial name.
  EXPECT_EQ(video_frames(dir_ / "overlay.mp4"), frames);
  EXPECT_FALSE(fs::exists(dir_ / "overlay.mp4.partial.mp4"));
  EXPECT_NE(sg::test::slurp(dir_ / "stdout.txt").find("interrupted"), std::string::npos);
}

INSTANTIATE_TEST_SUITE_P(Signals, StopSignal, ::testing::Values(SIGINT, SIGTERM),
                         [](const auto& info) { return info.param == SIGINT ? "Int" : "Term"; });

TEST_F(CliStop, RunToTheEndIsNotInterrupted) {
  const sg::test::CliResult r =
      sg::test::run_cli(dir_, "run --scenario head-on --scale 0.25 --quiet --summary s.json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(nlohmann::json::parse(sg::test::slurp(dir_ / "s.json")).at("interrupted").get<bool>());
}

TEST_F(CliStop, ShowWithoutADisplayIsOneLineAndExitTwoBeforeAnyOutput) {
  const pid_t pid = sg::test::spawn(
      {SG_STEREOGUARD_BIN, "run", "--scenario", "head-on", "--show", "--events", "events.jsonl",
       "--overlay", "overlay.mp4", "--summary", "summary.json"},
      dir_, dir_ / "stdout.txt", dir_ / "stderr.txt", {"DISPLAY=", "WAYLAND_DISPLAY="});
  const std::optional<int> status = sg::test::wait_exit(pid, 120s);
  ASSERT_TRUE(status);
  EXPECT_EQ(*status, 2);
  const std::string err = sg::test::slurp(dir_ / "stderr.txt");
  EXPECT_EQ(err.find('\n'), err.size() - 1) << "not one line: " << err;
  EXPECT_NE(err.find("--show"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir_ / "events.jsonl"));
  EXPECT_FALSE(fs::exists(dir_ / "overlay.mp4.partial.mp4"));
  EXPECT_FALSE(fs::exists(dir_ / "summary.json"));
}

TEST_F(CliStop, HelpDescribesEveryInputKind) {
  const sg::test::CliResult r = sg::test::run_cli(dir_, "run --help");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* kind : {"scenario", "stereo folder", "videos", "KITTI", "EuRoC", "camera"})
    EXPECT_NE(r.out.find(kind), std::string::npos) << kind;
}

}  // namespace
