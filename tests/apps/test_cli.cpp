// Runs the stereoguard binary on bad and good input: one clear line and exit status 2 for every
// user error, valid event lines whatever happens, reproducible output.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;

struct Result {
  int status = -1;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) / ("sg_cli_" + std::string(info->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  Result run(const std::string& args) {
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string cmd = std::string("cd '") + dir_.string() + "' && '" SG_STEREOGUARD_BIN "' " +
                            args + " >'" + out.string() + "' 2>'" + err.string() + "'";
    const int raw = std::system(cmd.c_str());
    Result r;
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
  }

  /// A small scenario file: a box approaching, 12 frames at 320x240.
  fs::path small_scenario(int frames = 12) {
    const fs::path p = dir_ / "small.yaml";
    std::ofstream(p) << "name: small\nframes: " << frames << "\n"
                     << "camera: {width: 321, height: 241, focal_px: 250, cx: 160, cy: 120}\n"
                     << "obstacles:\n"
                     << "  - {id: 1, size_m: [1.0, 1.5, 0.5], position_m: [0, 0.45, 4.0], "
                        "velocity_mps: [0, 0, -3]}\n";
    return p;
  }

  /// A stereo folder of the small scenario, written by `simulate`.
  fs::path small_folder(int frames = 12) {
    const fs::path folder = dir_ / "folder";
    const Result r = run("simulate --scenario '" + small_scenario(frames).string() + "' --out '" +
                         folder.string() + "'");
    EXPECT_EQ(r.status, 0) << r.err;
    return folder;
  }

  /// Expects exit status 2 and exactly one line on stderr that mentions `needle`.
  void expect_user_error(const Result& r, const std::string& needle) {
    EXPECT_EQ(r.status, 2) << r.err;
    ASSERT_FALSE(r.err.empty());
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "more than one line: " << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
  }

  fs::path dir_;
};

std::vector<nlohmann::json> read_events(const fs::path& p) {
  std::vector<nlohmann::json> events;
  std::ifstream in(p);
  std::string line;
  while (std::getline(in, line)) events.push_back(nlohmann::json::parse(line));  // throws if bad
  return events;
}

TEST_F(Cli, MissingFolder) {
  expect_user_error(run("run --input no_such_folder"), "no_such_folder");
}

TEST_F(Cli, MissingCameraYaml) {
  const fs::path folder = small_folder(3);
  fs::remove(folder / "camera.yaml");
  expect_user_error(run("run --input '" + folder.string() + "'"), "camera.yaml");
}

TEST_F(Cli, CameraYamlMissingField) {
  const fs::path folder = small_folder(3);
  std::ofstream(folder / "camera.yaml") << "focal_px: 250\ncx: 160\ncy: 120\nfps: 30\n";
  expect_user_error(run("run --input '" + folder.string() + "'"), "baseline_m");
}

TEST_F(Cli, CameraYamlNegativeFps) {
  const fs::path folder = small_folder(3);
  std::ofstream(folder / "camera.yaml")
      << "focal_px: 250\nbaseline_m: 0.12\ncx: 160\ncy: 120\nfps: -30\n";
  expect_user_error(run("run --input '" + folder.string() + "'"), "fps");
}

TEST_F(Cli, LeftRightCountsDiffer) {
  const fs::path folder = small_folder(3);
  fs::remove(folder / "right" / "000002.png");
  expect_user_error(run("run --input '" + folder.string() + "'"), "right");
}

TEST_F(Cli, LeftRightSizesDiffer) {
  const fs::path folder = small_folder(3);
  cv::Mat right = cv::imread((folder / "right" / "000000.png").string(), cv::IMREAD_GRAYSCALE);
  cv::imwrite((folder / "right" / "000000.png").string(), right(cv::Rect(0, 0, 100, 100)).clone());
  expect_user_error(run("run --input '" + folder.string() + "'"), "000000.png");
}

TEST_F(Cli, CorruptPngMidSequenceKeepsEventsValid) {
  const fs::path folder = small_folder(6);
  std::ofstream(folder / "left" / "000004.png", std::ios::binary) << "not a png at all";
  const fs::path events = dir_ / "events.jsonl";
  const Result r = run("run --input '" + folder.string() + "' --events '" + events.string() + "'");
  expect_user_error(r, "000004.png");
  const auto lines = read_events(events);
  ASSERT_EQ(lines.size(), 4u);  // frames 0..3, each a complete JSON object
  for (size_t i = 0; i < lines.size(); ++i) EXPECT_EQ(lines[i]["frame"], i);
}

TEST_F(Cli, FailedRunLeavesNoOverlay) {
  const fs::path folder = small_folder(4);
  std::ofstream(folder / "left" / "000002.png", std::ios::binary) << "garbage";
  const Result r = run("run --input '" + folder.string() + "' --overlay out.mp4");
  EXPECT_EQ(r.status, 2);
  EXPECT_FALSE(fs::exists(dir_ / "out.mp4"));
  EXPECT_FALSE(fs::exists(dir_ / "out.mp4.partial.mp4"));
}

TEST_F(Cli, UnknownScenario) {
  expect_user_error(run("run --scenario no-such-scenario"), "head-on");
}

TEST_F(Cli, EvenBlockSize) {
  expect_user_error(run("run --scenario '" + small_scenario().string() + "' --block-size 10"),
                    "block_size=10");
}

TEST_F(Cli, NumDisparitiesNotMultipleOf16) {
  expect_user_error(
      run("run --scenario '" + small_scenario().string() + "' --num-disparities 70"),
      "num_disparities=70");
}

TEST_F(Cli, NegativeFps) {
  expect_user_error(run("run --scenario '" + small_scenario().string() + "' --fps -5"), "fps=-5");
}

TEST_F(Cli, BadConfigKey) {
  std::ofstream(dir_ / "bad.yaml") << "stereo:\n  block_sise: 9\n";
  expect_user_error(run("run --scenario '" + small_scenario().string() + "' --config bad.yaml"),
                    "stereo.block_sise");
}

TEST_F(Cli, UnknownOptionIsExitTwo) {
  const Result r = run("run --no-such-option");
  EXPECT_EQ(r.status, 2);
}

TEST_F(Cli, RepeatedRunsGiveByteIdenticalEvents) {
  const std::string scenario = small_scenario().string();
  ASSERT_EQ(run("run --quiet --no-timing --scenario '" + scenario + "' --events a.jsonl").status, 0);
  ASSERT_EQ(run("run --quiet --no-timing --scenario '" + scenario + "' --events b.jsonl").status, 0);
  const std::string a = slurp(dir_ / "a.jsonl");
  EXPECT_EQ(read_events(dir_ / "a.jsonl").size(), 12u);
  EXPECT_EQ(a, slurp(dir_ / "b.jsonl"));
  EXPECT_EQ(a.find("latency_ms"), std::string::npos);
}

TEST_F(Cli, EventsCarryTheDocumentedFields) {
  ASSERT_EQ(run("run --quiet --scenario '" + small_scenario().string() + "' --events e.jsonl")
                .status,
            0);
  const auto events = read_events(dir_ / "e.jsonl");
  ASSERT_EQ(events.size(), 12u);
  for (const char* key : {"frame", "time_s", "signal", "severity", "steering", "regions",
                          "obstacles", "latency_ms"}) {
    EXPECT_TRUE(events.back().contains(key)) << key;
  }
  EXPECT_EQ(events.back()["regions"].size(), 3u);
}

TEST_F(Cli, OverlayHasOneFramePerProcessedFrame) {
  const Result r = run("run --scenario '" + small_scenario().string() + "' --overlay v.mp4");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("frames processed  12"), std::string::npos) << r.out;
  cv::VideoCapture video((dir_ / "v.mp4").string());
  ASSERT_TRUE(video.isOpened());
  int frames = 0;
  for (cv::Mat f; video.read(f);) ++frames;
  EXPECT_EQ(frames, 12);
}

TEST_F(Cli, FolderAndScenarioGiveTheSameEvaluation) {
  const fs::path folder = small_folder();
  ASSERT_EQ(run("eval --input '" + folder.string() + "' --json folder.json").status, 0);
  ASSERT_EQ(run("eval --scenario '" + small_scenario().string() + "' --json scenario.json").status,
            0);
  auto a = nlohmann::json::parse(slurp(dir_ / "folder.json"));
  auto b = nlohmann::json::parse(slurp(dir_ / "scenario.json"));
  a.erase("input");
  b.erase("input");
  EXPECT_EQ(a, b);
  EXPECT_GT(a["gt_alarm_frames"].get<int>(), 0);  // the small scenario does approach
}

TEST_F(Cli, EvalWithoutGroundTruth) {
  const fs::path folder = small_folder(3);
  fs::remove_all(folder / "gt");
  expect_user_error(run("eval --input '" + folder.string() + "'"), "ground truth");
}

}  // namespace
