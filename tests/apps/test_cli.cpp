// Runs the stereoguard binary on bad and good input: one clear line and exit status 2 for every
// user error, valid event lines whatever happens, reproducible output.
#include <gtest/gtest.h>

#include <cmath>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <optional>
#include <algorithm>
#include <sstream>
#include <string>

#include "cli_run.hpp"

namespace {

namespace fs = std::filesystem;

using Result = sg::test::CliResult;
using sg::test::slurp;

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) / ("sg_cli_" + std::string(info->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  Result run(const std::string& args) { return sg::test::run_cli(dir_, args); }

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

// The sequential run (one worker, one tile) delivers every frame before the broken one; a
// parallel one stops at the error too, and what it delivered is a prefix of those frames (a frame
// still in flight is lost), each line a complete JSON object.
TEST_F(Cli, CorruptPngMidSequenceKeepsEventsValid) {
  const fs::path folder = small_folder(6);
  std::ofstream(folder / "left" / "000004.png", std::ios::binary) << "not a png at all";
  const fs::path events = dir_ / "events.jsonl";
  for (const char* workers : {"1 --tiles 1", "auto"}) {
    const Result r = run("run --workers " + std::string(workers) + " --input '" +
                         folder.string() + "' --events '" + events.string() + "'");
    expect_user_error(r, "000004.png");
    const auto lines = read_events(events);
    if (std::string(workers) != "auto") {
      ASSERT_EQ(lines.size(), 4u);  // frames 0..3
    } else {
      ASSERT_LE(lines.size(), 4u);
    }
    for (size_t i = 0; i < lines.size(); ++i) EXPECT_EQ(lines[i]["frame"], i) << workers;
  }
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

TEST_F(Cli, EveryDetectorRunsAndNamesItsBadParameters) {
  // Each surveyed detector evaluates the small scenario, and a bad field of its own section is
  // one line naming it with exit status 2.
  const std::string scenario = small_scenario(6).string();
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"motion-parallax", "motion_parallax: {smooth_px: 4}"},
      {"relative-size", "relative_size: {gap_frames: 0}"},
      {"elevation-map", "elevation: {height_min_m: -0.1}"},
      {"sceneflow-seg", "sceneflow_seg: {sigma_flow_px: 0}"},
      {"longseq", "proximity: {alarm_distance_m: 0.2}"}};
  for (const auto& [detector, yaml] : bad) {
    const Result ok = run("eval --quiet --scenario '" + scenario + "' --detector " + detector);
    EXPECT_EQ(ok.status, 0) << detector << ": " << ok.err;
    EXPECT_NE(ok.out.find("(mode " + detector + ")"), std::string::npos) << ok.out;
    std::ofstream(dir_ / "bad.yaml") << yaml << "\n";
    const std::string field = yaml.substr(0, yaml.find(':')) + "." +
                              yaml.substr(yaml.find('{') + 1, yaml.find(':', yaml.find('{')) -
                                                                  yaml.find('{') - 1);
    expect_user_error(run("run --quiet --scenario '" + scenario + "' --detector " + detector +
                          " --config bad.yaml"),
                      field);
  }
  expect_user_error(run("run --scenario '" + scenario + "' --detector optic-flow"),
                    "detector=optic-flow: must be one of");
  expect_user_error(run("run --scenario '" + scenario + "' --detector longseq --matcher fast"),
                    "stereo.matcher=fast: must be longseq with the longseq detector");
  // --gaps means nothing to them: an error, not a flag silently ignored.
  expect_user_error(run("run --scenario '" + scenario + "' --detector motion-parallax --gaps 1,4"),
                    "gaps: the motion-parallax detector compares no frame gaps");
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

// Platform presets: the car preset's 128 disparities do not fit a 120 px wide image, so whether
// it was applied shows in the validation error.
TEST_F(Cli, ScenarioPlatformIsAppliedUnlessAFlagOrConfigSaysOtherwise) {
  std::ofstream(dir_ / "narrow.yaml")
      << "name: narrow\nframes: 3\nplatform: car\n"
      << "camera: {width: 120, height: 90, focal_px: 100, cx: 60, cy: 45}\n"
      << "obstacles:\n  - {id: 1, size_m: [1, 1, 1], position_m: [0, 0.7, 6]}\n";
  // The range comes from the camera and the preset's contact plane (f B = 12 px m: 16 px reach
  // 0.8 m, beyond the robot's 0.5 m contact, so 32; the car's 2 m need 16); the first line of run
  // names the depth it measures.
  const auto first_line = [&](const std::string& args) {
    const Result r = run("run --scenario narrow.yaml --quiet " + args);
    EXPECT_EQ(r.status, 0) << r.err;
    return r.out.substr(0, r.out.find('\n'));
  };
  EXPECT_NE(first_line("").find("depth 0.80-60 m"), std::string::npos) << first_line("");
  EXPECT_NE(first_line("--platform robot").find("depth 0.39-20 m"), std::string::npos);
  std::ofstream(dir_ / "robot.yaml") << "platform: robot\n";
  EXPECT_NE(first_line("--config robot.yaml").find("depth 0.39-20 m"), std::string::npos);
  // A config key wins over the derived value (f B / 47 = 0.26 m).
  std::ofstream(dir_ / "range.yaml") << "stereo: {num_disparities: 48}\n";
  EXPECT_NE(first_line("--config range.yaml").find("depth 0.26-60 m"), std::string::npos);
  std::ofstream(dir_ / "car.yaml") << "platform: car\n";
  expect_user_error(run("eval --scenario narrow.yaml --config car.yaml --platform walker "
                        "--num-disparities 256"),
                    "num_disparities=256");  // flags still override the preset and the camera
}

// run and eval default to Stereo-Flow (the mode we recommend); a config file or --mode picks
// Stereo. The summary's configuration names the mode that ran.
TEST_F(Cli, RunAndEvalDefaultToStereoFlowUnlessAConfigOrFlagSaysStereo) {
  const fs::path scenario = small_scenario(3);
  const auto mode_of = [&](const std::string& args) {
    const Result r = run(args + " --scenario '" + scenario.string() + "' --summary s.json");
    EXPECT_EQ(r.status, 0) << r.err;
    return nlohmann::json::parse(slurp(dir_ / "s.json"))["config"]["mode"].get<std::string>();
  };
  EXPECT_EQ(mode_of("run"), "stereo-flow");
  EXPECT_EQ(mode_of("run --mode stereo"), "stereo");
  std::ofstream(dir_ / "stereo.yaml") << "mode: stereo\n";
  EXPECT_EQ(mode_of("run --config stereo.yaml"), "stereo");
  EXPECT_EQ(mode_of("run --config stereo.yaml --mode stereo-flow"), "stereo-flow");
  const Result r = run("eval --scenario '" + scenario.string() + "' --json e.json");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("stereo-flow"), std::string::npos) << r.out;
}

// W and T default to auto, from the cores of the task arena: one worker per core, two tiles on
// more than one; a flag or config value wins, and the summary names what ran.
TEST_F(Cli, WorkersAndTilesDefaultToTheCores) {
  const fs::path scenario = small_scenario(3);
  const auto ran = [&](const std::string& args) {
    const Result r = run("run --scenario '" + scenario.string() + "' --summary s.json " + args);
    EXPECT_EQ(r.status, 0) << r.err;
    const nlohmann::json c = nlohmann::json::parse(slurp(dir_ / "s.json"))["config"];
    return std::make_pair(c["workers"].get<int>(), c["tiles"].get<int>());
  };
  EXPECT_EQ(ran("--threads 1"), std::make_pair(1, 1));
  EXPECT_EQ(ran("--threads 3"), std::make_pair(3, 2));
  EXPECT_EQ(ran("--threads 3 --workers 2 --tiles 1"), std::make_pair(2, 1));
  std::ofstream(dir_ / "w.yaml") << "workers: 1\ntiles: auto\n";
  EXPECT_EQ(ran("--threads 3 --config w.yaml"), std::make_pair(1, 2));
  const auto [w, t] = ran("");  // all the cores this process may use
  EXPECT_GE(w, 1);
  EXPECT_EQ(t, w > 1 ? 2 : 1);
  expect_user_error(run("run --scenario '" + scenario.string() + "' --workers many"), "--workers");
}

// Far approaches, where the per-frame disparity error of a small far surface is a tenth of its
// growth over the chain: with the two-point velocity of the longest gap these alarmed 0.1 s
// before the truth (false_alarm_rate 0.094 and 0.083); the velocity fit removed it.
TEST_F(Cli, StereoFlowAlarmsFarApproachesNeitherEarlyNorLate) {
  for (const char* scenario : {"head-on-fast", "car-stopped"}) {
    const Result r = run(std::string("eval --scenario ") + scenario + " --json e.json");
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json e = nlohmann::json::parse(slurp(dir_ / "e.json"));
    EXPECT_LE(e["false_alarm_rate"].get<double>(), 0.02) << scenario;
    EXPECT_GE(e["recall_settled"].get<double>(), 0.95) << scenario;
    ASSERT_EQ(e["lead_times_s"].size(), 1u) << scenario;
    EXPECT_GE(e["lead_times_s"][0]["lead_time_s"].get<double>(), 2.5) << scenario;
  }
}

// Issue 36: an obstacle already within the horizon when the run starts. Over the first frames
// (the chain still short of its window) each surface's velocity is doubted by the scatter of its
// own fit: the box of cold-start, a large face seen well, is trusted from the first frames the
// noise gate passes and alarms by frame 7 (with a fixed doubt of 0.6 px, at frame 15); the thin
// pole, whose first frames step by 0.6 px, gets no early alarm from them (with no doubt, 6 early
// frames: false_alarm_rate 0.082). Thin-pole is rendered with area-integrated silhouettes (the
// default edge_samples 4): point-sampled, its disparity steps by half a pixel and it alarms a frame
// early (0.014).
TEST_F(Cli, StereoFlowWarnsAtOnceOfAnApproachItsFirstFramesMeasureWell) {
  const Result cold = run("eval --scenario cold-start --json cold.json");
  ASSERT_EQ(cold.status, 0) << cold.err;
  const nlohmann::json c = nlohmann::json::parse(slurp(dir_ / "cold.json"));
  ASSERT_FALSE(c["first_alarm_frame"].is_null());
  EXPECT_LE(c["first_alarm_frame"].get<int>(), 7);
  EXPECT_EQ(c["false_alarm_rate"].get<double>(), 0.0);
  const Result pole = run("eval --scenario thin-pole --json pole.json");
  ASSERT_EQ(pole.status, 0) << pole.err;
  const nlohmann::json p = nlohmann::json::parse(slurp(dir_ / "pole.json"));
  EXPECT_LE(p["false_alarm_rate"].get<double>(), 0.01);
  EXPECT_GE(p["recall_settled"].get<double>(), 0.95);
}

// A car at 10 m/s through a 20 deg/s right-hand bend, parked cars and poles along both sides
// (examples/scenarios/car-turning.yaml at half size, 2 s): the straight line ahead runs into the
// parked cars outside the bend; the arc the car drives does not.
TEST_F(Cli, StereoFlowFollowsTheBendThePlatformIsIn) {
  const double w = 20.0 * CV_PI / 180.0, radius = 10.0 / w;
  std::ofstream yaml(dir_ / "bend.yaml");
  yaml << "frames: 60\nplatform: car\n"
       << "camera: {width: 480, height: 200, focal_px: 300, baseline_m: 0.3, cx: 239.5, cy: 99.5, "
          "fps: 30}\n"
       << "height_m: 1.3\nego_velocity_mps: [0, 0, 10]\nego_follows_heading: true\n"
       << "camera_motion: {yaw_rate_dps: 20}\nbackground_z_m: 150\nbackground_height_m: 30\n"
       << "envelope: {half_width_m: 1.0, y_top_m: -0.4, y_bottom_m: 1.1, z_contact_m: 2.0, "
          "horizon_s: 3}\nobstacles:\n";
  int id = 1;
  const auto add = [&](double rho, double deg, double sx, double sy, double sz) {
    const double a = deg * CV_PI / 180.0;
    yaml << "  - {id: " << id << ", size_m: [" << sx << ", " << sy << ", " << sz
         << "], position_m: [" << radius - rho * std::cos(a) << ", " << 1.3 - sy / 2 << ", "
         << rho * std::sin(a) << "], texture_seed: " << 1400 + id << "}\n";
    ++id;
  };
  for (int deg = 12; deg < 100; deg += 10) {
    add(radius + 4.5, deg, 1.8, 1.5, 4.5);    // parked cars outside the bend
    add(radius - 4.0, deg + 5, 0.2, 3.0, 0.2);  // poles inside
    add(radius + 3.2, deg + 5, 0.2, 3.0, 0.2);  // poles outside
  }
  yaml.close();
  std::ofstream(dir_ / "straight.yaml") << "scene_flow: {predict_turn: false}\n";
  const std::string scene = "eval --scenario '" + (dir_ / "bend.yaml").string() + "'";
  const Result arc = run(scene + " --json arc.json");
  ASSERT_EQ(arc.status, 0) << arc.err;
  const nlohmann::json a = nlohmann::json::parse(slurp(dir_ / "arc.json"));
  EXPECT_EQ(a["gt_alarm_frames"].get<int>(), 0);
  EXPECT_LE(a["false_alarm_rate"].get<double>(), 0.02);
  const Result line = run(scene + " --config '" + (dir_ / "straight.yaml").string() +
                          "' --json line.json");
  ASSERT_EQ(line.status, 0) << line.err;
  const nlohmann::json l = nlohmann::json::parse(slurp(dir_ / "line.json"));
  EXPECT_GE(l["false_alarm_rate"].get<double>(), 0.5);  // the scene does test the bend
}

TEST_F(Cli, UnknownPlatform) {
  expect_user_error(run("run --scenario '" + small_scenario().string() + "' --platform boat"),
                    "unknown platform 'boat'");
}

TEST_F(Cli, EvalWithoutGroundTruth) {
  const fs::path folder = small_folder(3);
  fs::remove_all(folder / "gt");
  expect_user_error(run("eval --input '" + folder.string() + "'"), "ground truth");
}

}  // namespace

namespace {

TEST_F(Cli, BenchWritesOneCsvRowPerConfigurationBesideItsBaselines) {
  const Result r = run(
      "bench --modes stereo --workers 1,2 --tiles 1,3 --resolutions 161x121 --frames 12 "
      "--pace 2 --csv b.csv --plot b.png");
  ASSERT_EQ(r.status, 0) << r.err;
  std::ifstream csv(dir_ / "b.csv");
  std::vector<std::string> rows;
  for (std::string line; std::getline(csv, line);) rows.push_back(line);
  // header, baseline, opencv-mt, 4 pipeline configurations, 2 more capacity runs of the best
  // one, 1 paced run, 1 recheck run of the best one after it
  ASSERT_EQ(rows.size(), 11u) << r.out;
  EXPECT_EQ(rows[0].rfind("kind,mode,width,height,workers,tiles", 0), 0u);
  EXPECT_EQ(rows[1].rfind("baseline,stereo,161,121,", 0), 0u) << rows[1];
  EXPECT_EQ(rows[2].rfind("opencv-mt,stereo,161,121,", 0), 0u) << rows[2];
  for (int i = 3; i < 7; ++i) {
    EXPECT_EQ(rows[i].rfind("pipeline,stereo,161,121,", 0), 0u) << rows[i];
    // Every configuration detects exactly what the plain loop detects.
    // same_detections, before the last column (speedup_1t)
    const std::string head = rows[i].substr(0, rows[i].rfind(','));
    EXPECT_EQ(head.substr(head.rfind(',') + 1), "yes") << rows[i];
  }
  EXPECT_EQ(rows[7].rfind("capacity,stereo,161,121,", 0), 0u) << rows[7];
  EXPECT_EQ(rows[8].rfind("capacity,stereo,161,121,", 0), 0u) << rows[8];
  EXPECT_EQ(rows[9].rfind("paced,stereo,161,121,", 0), 0u) << rows[9];
  EXPECT_EQ(rows[10].rfind("recheck,stereo,161,121,", 0), 0u) << rows[10];
  // The pace is 2 x the median fps of the best configuration's three runs (its sweep row and the
  // two capacity rows, which share its W and T).
  auto field = [](const std::string& row, int k) {
    std::stringstream s(row);
    std::string f;
    for (int i = 0; i <= k; ++i) std::getline(s, f, ',');
    return f;
  };
  std::vector<double> capacity;
  for (int i = 3; i < 9; ++i)
    if (field(rows[i], 4) == field(rows[9], 4) && field(rows[i], 5) == field(rows[9], 5))
      capacity.push_back(std::stod(field(rows[i], 11)));
  ASSERT_EQ(capacity.size(), 3u);
  std::sort(capacity.begin(), capacity.end());
  EXPECT_NEAR(std::stod(field(rows[9], 7)), 2 * capacity[1], 1e-3 * capacity[1]);
  // The text names that capacity, its runs and their spread before the paced row.
  const std::string told = "(paced rows: fractions of ";
  const size_t at = r.out.find(told);
  ASSERT_NE(at, std::string::npos) << r.out;
  EXPECT_LT(at, r.out.find("\npaced ")) << r.out;
  EXPECT_NEAR(std::stod(r.out.substr(at + told.size())), capacity[1], 0.051) << r.out;
  const std::string runs = " fps, the median of 3 runs of W " + field(rows[9], 4) + " T " +
                           field(rows[9], 5) + ", spread ";
  const size_t spread = r.out.find(runs, at);
  ASSERT_NE(spread, std::string::npos) << runs << "\n" << r.out;
  EXPECT_NEAR(std::stod(r.out.substr(spread + runs.size())),
              100.0 * (capacity[2] - capacity[0]) / capacity[1], 0.051)
      << r.out;
  // The recheck runs the paced configuration unpaced and says how far it is from that capacity.
  EXPECT_EQ(field(rows[10], 4), field(rows[9], 4));
  EXPECT_EQ(field(rows[10], 5), field(rows[9], 5));
  EXPECT_EQ(std::stod(field(rows[10], 7)), 0.0);
  const std::string after = "(after the paced rows: W " + field(rows[9], 4) + " T " +
                            field(rows[9], 5) + " ran ";
  const size_t again = r.out.find(after);
  ASSERT_NE(again, std::string::npos) << r.out;
  EXPECT_GT(again, r.out.find("\nrecheck ")) << r.out;
  const double recheck_fps = std::stod(field(rows[10], 11));
  EXPECT_NEAR(std::stod(r.out.substr(again + after.size())), recheck_fps, 0.051) << r.out;
  const size_t off_at = r.out.find(" fps, ", again + after.size());
  ASSERT_NE(off_at, std::string::npos) << r.out;
  EXPECT_NEAR(std::stod(r.out.substr(off_at + 6)), 100.0 * (recheck_fps / capacity[1] - 1.0),
              0.051)
      << r.out;
  EXPECT_GT(fs::file_size(dir_ / "b.png"), 1000u);
  // The pipeline rows use run's default matcher (it once said fast and ran bm).
  EXPECT_NE(r.out.find("pipeline rows: matcher fast (baselines: bm)"), std::string::npos) << r.out;
}

TEST_F(Cli, BenchRejectsBadSettings) {
  expect_user_error(run("bench --resolutions 640by480"), "640by480");
  expect_user_error(run("bench --workers 0 --frames 12"), "workers=0");
  expect_user_error(run("bench --capacity-runs 0 --frames 12"), "capacity_runs=0");
}

}  // namespace

namespace {

TEST_F(Cli, CorruptPngWithParallelPipelineIsStillACleanError) {
  const fs::path folder = small_folder(8);
  std::ofstream(folder / "left" / "000005.png", std::ios::binary) << "not a png";
  const fs::path events = dir_ / "events.jsonl";
  const Result r = run("run --workers 2 --tiles 3 --input '" + folder.string() + "' --events '" +
                       events.string() + "'");
  expect_user_error(r, "000005.png");
  const auto lines = read_events(events);  // complete lines only, in order
  EXPECT_LE(lines.size(), 5u);
  for (size_t i = 0; i < lines.size(); ++i) EXPECT_EQ(lines[i]["frame"], i);
}

TEST_F(Cli, InvalidParallelOptions) {
  expect_user_error(run("run --scenario '" + small_scenario().string() + "' --workers 0"),
                    "--workers must be a positive integer or auto");
  expect_user_error(run("run --scenario '" + small_scenario().string() + "' --tiles 100"),
                    "tiles=100");
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Stereo-Flow mode and `eval --flow`

namespace {

/// Middlebury .flo: "PIEH" (202021.25 as float), width, height, then (u, v) floats row by row.
void write_flo_file(const fs::path& p, const cv::Mat& flow) {
  std::ofstream out(p, std::ios::binary);
  const float tag = 202021.25f;
  const int32_t w = flow.cols, h = flow.rows;
  out.write(reinterpret_cast<const char*>(&tag), 4);
  out.write(reinterpret_cast<const char*>(&w), 4);
  out.write(reinterpret_cast<const char*>(&h), 4);
  for (int y = 0; y < h; ++y) out.write(flow.ptr<char>(y), static_cast<std::streamsize>(w) * 8);
}

/// A smooth random texture and the same moved by (dx, dy) px: GT forward flow (dx, dy).
void write_shifted_pair(const fs::path& a, const fs::path& b, const fs::path& gt, cv::Size size,
                        int dx, int dy) {
  cv::RNG rng(77);
  cv::Mat big(size.height + 40, size.width + 40, CV_8U);
  rng.fill(big, cv::RNG::UNIFORM, 0, 256);
  cv::Mat smooth;
  cv::GaussianBlur(big, smooth, cv::Size(0, 0), 1.5);
  cv::normalize(smooth, smooth, 0, 255, cv::NORM_MINMAX);
  const cv::Rect r(20, 20, size.width, size.height);
  cv::imwrite(a.string(), smooth(r));
  cv::imwrite(b.string(), smooth(r - cv::Point(dx, dy)));  // content moves by (+dx, +dy)
  write_flo_file(gt, cv::Mat(size, CV_32FC2, cv::Scalar(dx, dy)));
}

/// EPE of `method` in the table that `eval --flow` prints for `pair`; -1 when absent.
double printed_epe(const std::string& out, const std::string& pair, const std::string& method) {
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream words(line);
    std::string p, m;
    double epe = -1;
    if (words >> p >> m >> epe && p == pair && m == method) return epe;
  }
  return -1;
}

TEST_F(Cli, StereoFlowRepeatedRunsGiveByteIdenticalEventsWithVelocities) {
  const std::string scenario = small_scenario(24).string();
  const std::string common = "run --quiet --no-timing --mode stereo-flow --scenario '" + scenario;
  ASSERT_EQ(run(common + "' --events a.jsonl").status, 0);
  ASSERT_EQ(run(common + "' --events b.jsonl --workers 2").status, 0);
  const std::string a = slurp(dir_ / "a.jsonl");
  EXPECT_EQ(a, slurp(dir_ / "b.jsonl"));
  const auto events = read_events(dir_ / "a.jsonl");
  ASSERT_EQ(events.size(), 24u);
  // The box approaches at 3 m/s: by the end it is an obstacle with a velocity towards us.
  int with_velocity = 0;
  for (const auto& e : events)
    for (const auto& o : e["obstacles"])
      if (o.contains("velocity_mps")) {
        ++with_velocity;
        EXPECT_LT(o["velocity_mps"][2].get<double>(), -1.5) << e.dump();
      }
  EXPECT_GT(with_velocity, 5);
}

TEST_F(Cli, FlowMethodFlagAndConfigSection) {
  const std::string scenario = small_scenario(6).string();
  EXPECT_EQ(run("run --quiet --mode stereo-flow --flow-method farneback --scenario '" + scenario +
                "'")
                .status,
            0);
  expect_user_error(run("run --mode stereo-flow --flow-method dis --scenario '" + scenario + "'"),
                    "flow.method=dis");
  std::ofstream(dir_ / "bad.yaml") << "mode: stereo-flow\nscene_flow:\n  v_min_mps: -1\n";
  expect_user_error(run("run --config bad.yaml --scenario '" + scenario + "'"),
                    "scene_flow.v_min_mps=-1");
}

TEST_F(Cli, EvalFlowOnASyntheticPairAndFolders) {
  write_shifted_pair(dir_ / "a.png", dir_ / "b.png", dir_ / "gt.flo", {161, 121}, 3, -2);
  Result r = run("eval --flow --left a.png --right b.png --gt gt.flo --json flow.json");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* m : {"dis-ultrafast", "dis-fast", "dis-medium", "farneback"}) {
    const double epe = printed_epe(r.out, "a", m);
    EXPECT_GE(epe, 0.0) << m << "\n" << r.out;
    EXPECT_LT(epe, 1.0) << m;  // zero flow would be 3.6 px
  }
  const auto j = nlohmann::json::parse(slurp(dir_ / "flow.json"));
  EXPECT_EQ(j["flow"].size(), 4u);
  // Folder forms: Middlebury (NAME1, NAME2, NAME.flo) in a subfolder, FlyingChairs beside it.
  fs::create_directories(dir_ / "d" / "Shift");
  write_shifted_pair(dir_ / "d" / "Shift" / "Shift1.png", dir_ / "d" / "Shift" / "Shift2.png",
                     dir_ / "d" / "Shift" / "Shift.flo", {97, 75}, -2, 1);
  write_shifted_pair(dir_ / "d" / "0000007-img0.pgm", dir_ / "d" / "0000007-img1.pgm",
                     dir_ / "d" / "0000007-gt.flo", {97, 75}, 1, 2);
  r = run("eval --flow --dir d --flow-methods dis-medium");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_GE(printed_epe(r.out, "Shift", "dis-medium"), 0.0) << r.out;
  EXPECT_LT(printed_epe(r.out, "Shift", "dis-medium"), 1.0) << r.out;
  EXPECT_GE(printed_epe(r.out, "0000007", "dis-medium"), 0.0) << r.out;
  EXPECT_GE(printed_epe(r.out, "mean", "dis-medium"), 0.0) << r.out;
  EXPECT_LT(printed_epe(r.out, "0000007", "farneback"), 0.0);  // not asked for
}

TEST_F(Cli, EvalFlowBadInput) {
  write_shifted_pair(dir_ / "a.png", dir_ / "b.png", dir_ / "gt.flo", {161, 121}, 3, 0);
  write_shifted_pair(dir_ / "s.png", dir_ / "t.png", dir_ / "small.flo", {81, 61}, 3, 0);
  expect_user_error(run("eval --flow --left a.png --right missing.png --gt gt.flo"), "missing.png");
  expect_user_error(run("eval --flow --left a.png --right b.png --gt small.flo"), "sizes differ");
  std::ofstream(dir_ / "bad.flo", std::ios::binary) << "not a flo file at all";
  expect_user_error(run("eval --flow --left a.png --right b.png --gt bad.flo"), "bad.flo");
  expect_user_error(run("eval --flow --left a.png --right b.png"), "--gt");
  expect_user_error(run("eval --flow --dir nowhere"), "nowhere");
  fs::create_directories(dir_ / "empty");
  expect_user_error(run("eval --flow --dir empty"), "no pair found");
  expect_user_error(
      run("eval --flow --left a.png --right b.png --gt gt.flo --flow-methods dis-slow"),
      "dis-slow");
}

// DIS on real data (the acceptance): skipped when the shared data is absent.
TEST_F(Cli, EvalFlowOnMiddleburyAndFlyingChairs) {
  const fs::path data = fs::path(SG_SHARED_DIR) / "data";
  const fs::path rw = data / "middlebury_flow" / "RubberWhale";
  const fs::path fc = data / "flyingchairs_examples";
  if (!fs::exists(rw / "RubberWhale.flo") || !fs::exists(fc / "0000000-gt.flo"))
    GTEST_SKIP() << "no shared flow data under " << data;
  Result r = run("eval --flow --dir '" + rw.string() + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  std::printf("%s", r.out.c_str());
  // RubberWhale moves by at most a few px: every DIS preset stays well under 1 px, and the finer
  // presets are not worse than ultrafast.
  const double ultrafast = printed_epe(r.out, "RubberWhale", "dis-ultrafast");
  const double medium = printed_epe(r.out, "RubberWhale", "dis-medium");
  EXPECT_GT(ultrafast, 0.0);
  EXPECT_LT(ultrafast, 1.0);
  EXPECT_GT(medium, 0.0);
  EXPECT_LE(medium, ultrafast);
  r = run("eval --flow --dir '" + fc.string() + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  std::printf("%s", r.out.c_str());
  for (const char* m : {"dis-ultrafast", "dis-fast", "dis-medium"}) {
    const double epe = printed_epe(r.out, "mean", m);
    EXPECT_GT(epe, 0.0) << m;
    EXPECT_LT(epe, 8.0) << m;  // large chair motions; zero flow is about 10 px here
  }
}

// ---- Outputs (issue 7b): --csv, --dump, --scale, the progress bar ----

std::vector<std::vector<std::string>> read_csv(const fs::path& p) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(p);
  std::string line;
  while (std::getline(in, line)) {
    rows.emplace_back(1);
    for (char c : line) {
      if (c == ',')
        rows.back().emplace_back();
      else
        rows.back().back() += c;
    }
  }
  return rows;
}

TEST_F(Cli, CsvHasAHeaderAndOneRowPerFrameAgreeingWithTheEvents) {
  const Result r = run("run --quiet --scenario '" + small_scenario().string() +
                       "' --csv m.csv --events e.jsonl");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = read_csv(dir_ / "m.csv");
  const auto events = read_events(dir_ / "e.jsonl");
  ASSERT_EQ(rows.size(), 13u);
  ASSERT_EQ(events.size(), 12u);
  const std::vector<std::string> header = rows[0];
  ASSERT_EQ(header.size(), 11u);
  EXPECT_EQ(header[0], "frame");
  EXPECT_EQ(header[10], "latency_ms");
  int alarms = 0;
  for (size_t i = 1; i < rows.size(); ++i) {
    ASSERT_EQ(rows[i].size(), header.size()) << i;
    const auto& e = events[i - 1];
    EXPECT_EQ(std::stoi(rows[i][0]), e["frame"].get<int>());
    EXPECT_EQ(rows[i][2], e["signal"].get<bool>() ? "1" : "0");
    EXPECT_EQ(rows[i][3], e["severity"].get<std::string>());
    EXPECT_EQ(std::stoi(rows[i][7]), static_cast<int>(e["obstacles"].size()));
    EXPECT_FALSE(rows[i][10].empty());
    alarms += rows[i][2] == "1";
  }
  EXPECT_GT(alarms, 0);  // the small scenario's box approaches: the rows carry real alarms
  EXPECT_NE(r.out.find("csv               m.csv (12 rows)"), std::string::npos) << r.out;
}

TEST_F(Cli, CsvOfAFailedRunKeepsItsCompleteRows) {
  const fs::path folder = small_folder(6);
  std::ofstream(folder / "left" / "000004.png", std::ios::binary) << "not a png at all";
  // Sequential: every frame before the broken one (a parallel run may stop a frame sooner).
  const Result r =
      run("run --quiet --workers 1 --tiles 1 --input '" + folder.string() + "' --csv m.csv");
  expect_user_error(r, "000004.png");
  const auto rows = read_csv(dir_ / "m.csv");
  ASSERT_EQ(rows.size(), 5u);  // header + frames 0..3
  for (size_t i = 1; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].size(), rows[0].size());
    EXPECT_EQ(rows[i][0], std::to_string(i - 1));
  }
}

TEST_F(Cli, DumpWritesDisparityFlowAndDangerPngsPerFrame) {
  const Result r = run("run --quiet --mode stereo-flow --scenario '" + small_scenario(6).string() +
                       "' --dump out/d");
  ASSERT_EQ(r.status, 0) << r.err;
  const fs::path d = dir_ / "out" / "d";
  for (int i = 0; i < 6; ++i) {
    char name[32];
    for (const char* kind : {"disparity", "flow", "danger"}) {
      std::snprintf(name, sizeof name, "%s_%06d.png", kind, i);
      const bool expected = i > 0 || std::string(kind) != "flow";  // no flow for the first frame
      ASSERT_EQ(fs::exists(d / name), expected) << name;
      if (!expected) continue;
      const cv::Mat img = cv::imread((d / name).string(), cv::IMREAD_UNCHANGED);
      EXPECT_EQ(img.size(), cv::Size(321, 241)) << name;
      EXPECT_EQ(img.channels(), std::string(kind) == "danger" ? 1 : 3) << name;
    }
  }
}

TEST_F(Cli, DumpAndCsvBadPaths) {
  std::ofstream(dir_ / "file") << "x";
  const std::string scenario = " --scenario '" + small_scenario(2).string() + "'";
  expect_user_error(run("run" + scenario + " --dump file"), "--dump file");
  expect_user_error(run("run" + scenario + " --dump file/sub"), "--dump file/sub");
  expect_user_error(run("run" + scenario + " --csv no/such/dir/m.csv"), "--csv");
  expect_user_error(run("run" + scenario + " --csv"), "--csv");
}

TEST_F(Cli, ScaleResizesTheInputAndTheCamera) {
  const Result r = run("run --quiet --no-timing --scenario '" + small_scenario(4).string() +
                       "' --scale 0.5 --dump d --events e.jsonl");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("161x121"), std::string::npos) << r.out;  // 321x241 halved, rounded
  EXPECT_EQ(read_events(dir_ / "e.jsonl").size(), 4u);
  EXPECT_EQ(cv::imread((dir_ / "d" / "danger_000003.png").string(), cv::IMREAD_UNCHANGED).size(),
            cv::Size(161, 121));
  // The folder of the same scenario scales the same way.
  const Result f = run("run --quiet --no-timing --input '" + small_folder(4).string() +
                       "' --scale 0.5 --events f.jsonl");
  ASSERT_EQ(f.status, 0) << f.err;
  EXPECT_EQ(slurp(dir_ / "e.jsonl"), slurp(dir_ / "f.jsonl"));
}

TEST_F(Cli, ScaleBadValues) {
  const std::string scenario = " --scenario '" + small_scenario(2).string() + "'";
  for (const char* bad : {"0", "-1", "nan", "inf", "4.5", "abc", "0.1"}) {
    const Result r = run(std::string("run") + scenario + " --scale " + bad);
    SCOPED_TRACE(bad);
    expect_user_error(r, "--scale");
  }
  expect_user_error(run("eval" + scenario + " --scale 0.5"), "--scale");  // run only
}

TEST_F(Cli, ConfigFileSetsCsvDumpAndScale) {
  std::ofstream(dir_ / "c.yaml") << "scale: 0.5\ncsv: c.csv\ndump: cd\n";
  const Result r =
      run("run --quiet --config c.yaml --scenario '" + small_scenario(3).string() + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("161x121"), std::string::npos) << r.out;
  EXPECT_EQ(read_csv(dir_ / "c.csv").size(), 4u);
  EXPECT_TRUE(fs::exists(dir_ / "cd" / "danger_000002.png"));
  std::ofstream(dir_ / "bad.yaml") << "scale: 0\n";
  expect_user_error(run("run --config bad.yaml --scenario '" + small_scenario(3).string() + "'"),
                    "scale=0");
  std::ofstream(dir_ / "eval.yaml") << "scale: 0.5\n";
  expect_user_error(run("eval --config eval.yaml --scenario '" + small_scenario(3).string() + "'"),
                    "scale");
}

TEST_F(Cli, EvalWritesCsvAndDump) {
  const Result r = run("eval --scenario '" + small_scenario(4).string() + "' --csv m.csv --dump d");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(read_csv(dir_ / "m.csv").size(), 5u);
  EXPECT_TRUE(fs::exists(dir_ / "d" / "disparity_000003.png"));
}

/// Runs `args` with stderr (and stdout) on a pseudo-terminal through script(1); its output is
/// everything the terminal received. Empty optional when script(1) is missing.
std::optional<std::string> run_on_terminal(const fs::path& dir, const std::string& args) {
  if (std::system("command -v script >/dev/null 2>&1") != 0) return std::nullopt;
  const fs::path out = dir / "tty.txt";
  const std::string inner = "cd '" + dir.string() + "' && '" SG_STEREOGUARD_BIN "' " + args;
  const std::string cmd =
      "script -qfec \"" + inner + "\" /dev/null >'" + out.string() + "' 2>&1 </dev/null";
  if (std::system(cmd.c_str()) != 0) return std::string();
  return slurp(out);
}

TEST_F(Cli, ProgressBarOnATerminalOnly) {
  const std::string args = "run --scenario '" + small_scenario(6).string() + "'";
  const std::optional<std::string> tty = run_on_terminal(dir_, args);
  if (!tty) GTEST_SKIP() << "script(1) is not installed";
  EXPECT_NE(tty->find("6/6 frames"), std::string::npos) << *tty;
  EXPECT_NE(tty->find(" fps  ETA "), std::string::npos) << *tty;
  EXPECT_NE(tty->find("\033[K"), std::string::npos) << *tty;  // erased before the summary
  const std::optional<std::string> quiet = run_on_terminal(dir_, args + " --quiet");
  ASSERT_TRUE(quiet);
  EXPECT_NE(quiet->find("frames processed  6"), std::string::npos) << *quiet;
  EXPECT_EQ(quiet->find("/6 frames"), std::string::npos) << *quiet;
  // stderr is a file here, not a terminal: no bar.
  const Result r = run(args);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(r.out.find("/6 frames"), std::string::npos);
}

}  // namespace

namespace {

TEST_F(Cli, UnknownMatcherIsAUserError) {
  expect_user_error(run("run --scenario '" + small_scenario().string() + "' --matcher nope"),
                    "matcher=nope");
}

TEST_F(Cli, FastMatcherBlockTooLargeIsAUserError) {
  expect_user_error(run("run --scenario '" + small_scenario().string() +
                        "' --matcher fast --block-size 41"),
                    "block_size=41");
}

TEST_F(Cli, StereoEvalNeedsItsInputs) {
  expect_user_error(run("eval --stereo --left a.png"), "--stereo needs");
  expect_user_error(run("eval --stereo --dir no-such-dir"), "not a folder");
}

TEST_F(Cli, StereoEvalOnAPairWritesJsonPerMatcher) {
  // A synthetic pair: right = left shifted by 8 px; GT 8 px stored 8-bit with scale 4.
  cv::Mat wide(120, 200, CV_8U);
  cv::RNG(3).fill(wide, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(wide, wide, cv::Size(0, 0), 1.0);
  cv::imwrite((dir_ / "l.png").string(), wide(cv::Rect(0, 0, 160, 120)));
  cv::imwrite((dir_ / "r.png").string(), wide(cv::Rect(8, 0, 160, 120)));
  cv::imwrite((dir_ / "gt.png").string(), cv::Mat(120, 160, CV_8U, cv::Scalar(32)));
  const Result r = run(
      "eval --stereo --left l.png --right r.png --gt gt.png --gt-scale 4 --num-disparities 16 "
      "--matchers bm,fast,fast-census --json s.json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(slurp(dir_ / "s.json"));
  ASSERT_EQ(j["stereo"].size(), 3u);
  for (const auto& row : j["stereo"]) {
    EXPECT_LT(row["bad1"].get<double>(), 1.0) << row;
    EXPECT_GT(row["density"].get<double>(), 0.5) << row;
  }
}

}  // namespace
