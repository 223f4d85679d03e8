// `stereoguard eval --truth FILE [--baseline-method central-median]` as a user runs it: a bad
// truth log is one clear line and exit status 2; a good one gives the scores, as text and JSON.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "cli_run.hpp"

namespace {

namespace fs = std::filesystem;

using Result = sg::test::CliResult;
using sg::test::slurp;

class CliTruth : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) / ("sg_cli_truth_" + std::string(info->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // A box coming at the camera: 12 frames at 30 fps, 321 x 241.
    std::ofstream(dir_ / "small.yaml")
        << "name: small\nframes: 12\n"
        << "camera: {width: 321, height: 241, focal_px: 250, cx: 160, cy: 120}\n"
        << "obstacles:\n"
        << "  - {id: 1, size_m: [1.0, 1.5, 0.5], position_m: [0, 0.45, 4.0], "
           "velocity_mps: [0, 0, -3]}\n";
  }
  void TearDown() override { fs::remove_all(dir_); }

  Result run(const std::string& args) { return sg::test::run_cli(dir_, args); }

  fs::path write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p;
  }

  /// Exit status 2 and exactly one line on stderr that holds every needle.
  void expect_user_error(const Result& r, const std::vector<std::string>& needles) {
    EXPECT_EQ(r.status, 2) << r.err;
    ASSERT_FALSE(r.err.empty());
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "more than one line: " << r.err;
    EXPECT_EQ(r.err.rfind("stereoguard: error: ", 0), 0u) << r.err;
    for (const std::string& n : needles)
      EXPECT_NE(r.err.find(n), std::string::npos) << "'" << n << "' not in: " << r.err;
  }

  /// The truth of small.yaml: the box's front face at 3.75 - 3 t m, `rows` rows at 30 fps.
  std::string small_truth(int rows) {
    std::ostringstream s;
    s << "frame,t_s,distance_m\n";
    for (int i = 0; i < rows; ++i)
      s << i << "," << i / 30.0 << "," << 3.75 - 3.0 * i / 30.0 << "\n";
    return s.str();
  }

  fs::path dir_;
};

TEST_F(CliTruth, BadValueNamesFileLineAndColumn) {
  write("truth.csv", "frame,t_s,distance_m\n0,0.0,3.5\n1,0.033,three\n");
  expect_user_error(run("eval --scenario small.yaml --truth truth.csv"),
                    {"truth.csv line 3, column 3 (distance_m)", "'three'"});
}

TEST_F(CliTruth, MissingTruthFile) {
  expect_user_error(run("eval --scenario small.yaml --truth nowhere.csv"),
                    {"nowhere.csv", "does not exist"});
}

TEST_F(CliTruth, NoTimeColumn) {
  write("truth.csv", "index,distance_m\n0,3.5\n");
  expect_user_error(
      run("eval --scenario small.yaml --truth truth.csv --baseline-method central-median"),
      {"truth.csv line 1", "no 'frame' or 't_s' column"});
}

TEST_F(CliTruth, NonIncreasingFrames) {
  write("truth.csv", "frame,distance_m\n0,3.5\n0,3.4\n");
  expect_user_error(run("eval --scenario small.yaml --truth truth.csv"),
                    {"truth.csv line 3, column 1 (frame)", "does not increase"});
}

TEST_F(CliTruth, EmptyTruthFile) {
  write("truth.csv", "");
  expect_user_error(run("eval --scenario small.yaml --truth truth.csv"), {"truth.csv", "empty"});
}

TEST_F(CliTruth, UnknownBaselineAndOptionsWithoutTruth) {
  expect_user_error(run("eval --scenario small.yaml --baseline-method median"),
                    {"baseline-method=median", "central-median"});
  expect_user_error(run("eval --scenario small.yaml --due-within 0.85"), {"--truth"});
  write("truth.csv", small_truth(12));
  expect_user_error(run("eval --scenario small.yaml --truth truth.csv --due-within -1"),
                    {"due-within"});
}

TEST_F(CliTruth, ScoresTheDetectorAndWarnsAboutExtraRows) {
  write("truth.csv", small_truth(15));  // 3 rows more than frames
  const Result r = run("eval --quiet --scenario small.yaml --truth truth.csv --json e.json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("against truth.csv (stereoguard, mode stereo-flow)"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("due frames"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("warning: truth.csv has 3 rows past the last frame"), std::string::npos)
      << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(dir_ / "e.json"));
  EXPECT_EQ(j["frames"], 12);
  EXPECT_EQ(j["scored_frames"], 12);
  EXPECT_EQ(j["rows_past_last_frame"], 3);
  EXPECT_EQ(j["detector"], "stereoguard");
  // 3.75 m at 3 m/s: TTC (3.75 - 0.5) / 3 = 1.08 s at frame 0, so every frame is due.
  EXPECT_EQ(j["due_frames"], 12);
  EXPECT_EQ(j["quiet_frames"], 0);
  EXPECT_EQ(j["criteria"]["distance_column"], "distance_m");
}

TEST_F(CliTruth, ScoresTheBaselineAndCountsUnscoredFrames) {
  write("truth.csv", small_truth(8));  // 4 frames past the log
  const Result r =
      run("eval --quiet --scenario small.yaml --truth truth.csv --baseline-method central-median "
          "--json b.json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("(baseline central-median)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("unscored frames   4"), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(slurp(dir_ / "b.json"));
  EXPECT_EQ(j["detector"], "central-median");
  EXPECT_EQ(j["frames"], 12);
  EXPECT_EQ(j["unscored_frames"], 4);
}

TEST_F(CliTruth, BaselineWithoutTruthCountsAlarms) {
  const Result r = run("eval --quiet --scenario small.yaml --baseline-method central-median");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("no truth log: alarms only"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("alarm frames"), std::string::npos) << r.out;
}

}  // namespace
