// `stereoguard simulate --random` and `eval --suite random` as a user runs them: a generated
// scene is a stereo folder that eval scores; a small suite prints and writes finite figures; bad
// arguments are one clear line and exit status 2.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_run.hpp"

namespace {

namespace fs = std::filesystem;

using Result = sg::test::CliResult;

class CliRandom : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) / ("sg_cli_random_" + std::string(info->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  Result run(const std::string& args) { return sg::test::run_cli(dir_, args); }

  /// Exit status 2 and exactly one line on stderr holding `needle`.
  void expect_user_error(const Result& r, const std::string& needle) {
    EXPECT_EQ(r.status, 2) << r.err;
    ASSERT_FALSE(r.err.empty());
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "more than one line: " << r.err;
    EXPECT_EQ(r.err.rfind("stereoguard: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << "'" << needle << "' not in: " << r.err;
  }

  fs::path dir_;
};

bool finite_number(const nlohmann::json& j) {
  return j.is_number() && std::isfinite(j.get<double>());
}

TEST_F(CliRandom, SimulatedSceneIsScoredByEval) {
  const Result sim = run("simulate --random --seed 1234 --out scene --frames 12");
  ASSERT_EQ(sim.status, 0) << sim.err;
  EXPECT_TRUE(fs::exists(dir_ / "scene" / "gt" / "frames.jsonl"));
  const Result again = run("simulate --random --seed 1234 --out scene2 --frames 12");
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_EQ(sg::test::slurp(dir_ / "scene" / "gt" / "frames.jsonl"),
            sg::test::slurp(dir_ / "scene2" / "gt" / "frames.jsonl"));
  // The scene's own scenario.yaml renders it again.
  ASSERT_TRUE(fs::exists(dir_ / "scene" / "scenario.yaml"));
  const Result replay = run("simulate --scenario scene/scenario.yaml --out scene3");
  ASSERT_EQ(replay.status, 0) << replay.err;
  EXPECT_EQ(sg::test::slurp(dir_ / "scene" / "gt" / "frames.jsonl"),
            sg::test::slurp(dir_ / "scene3" / "gt" / "frames.jsonl"));
  EXPECT_EQ(sg::test::slurp(dir_ / "scene" / "left" / "000011.png"),
            sg::test::slurp(dir_ / "scene3" / "left" / "000011.png"));
  const Result eval = run("eval --input scene --json e.json");
  ASSERT_EQ(eval.status, 0) << eval.err;
  const nlohmann::json j = nlohmann::json::parse(sg::test::slurp(dir_ / "e.json"));
  EXPECT_EQ(j.at("frames").get<int>(), 12);
}

TEST_F(CliRandom, SmokeSuiteWritesFiniteFigures) {
  const Result r =
      run("eval --suite random --count 10 --seed 1000 --max-size 320x240 --max-frames 40 "
          "--json s.json --plot s.png");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("false alarm rate"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(dir_ / "s.png"));
  const nlohmann::json j = nlohmann::json::parse(sg::test::slurp(dir_ / "s.json"));
  const nlohmann::json& s = j.at("summary");
  EXPECT_EQ(s.at("scenes").get<int>(), 10);
  EXPECT_EQ(j.at("scenes").size(), 10u);
  EXPECT_EQ(s.at("colliding").get<int>() + s.at("clear").get<int>(), 10);
  for (const char* key :
       {"recall_settled", "lead_s", "lead_entering_s", "first_alarm_delay_s", "false_alarm_rate"})
    for (const char* stat : {"mean", "p10", "p50", "p90"})
      EXPECT_TRUE(finite_number(s.at(key).at(stat))) << key << "." << stat;
  int entering_scenes = 0;
  for (std::size_t i = 0; i < j.at("scenes").size(); ++i) {
    const nlohmann::json& scene = j.at("scenes")[i];
    EXPECT_EQ(scene.at("seed").get<long long>(), 1000 + static_cast<long long>(i));
    EXPECT_LE(scene.at("width").get<int>(), 320);
    EXPECT_LE(scene.at("frames").get<int>(), 40);
    EXPECT_TRUE(finite_number(scene.at("recall_settled")));
    EXPECT_TRUE(finite_number(scene.at("false_alarm_rate")));
    // What the scene drew, beside its description: the same motion, shapes and paths.
    const nlohmann::json& drawn = scene.at("scene");
    const std::string description = scene.at("description").get<std::string>();
    EXPECT_NE(description.find(", " + drawn.at("ego_motion").get<std::string>() + " at "),
              std::string::npos)
        << description;
    const auto shapes = drawn.at("shapes").get<std::vector<std::string>>();
    const auto paths = drawn.at("paths").get<std::vector<std::string>>();
    ASSERT_EQ(paths.size(), shapes.size());
    EXPECT_EQ(drawn.at("textures").size(), shapes.size());
    EXPECT_EQ(shapes.empty(), description.find("no obstacle") != std::string::npos);
    for (std::size_t k = 0; k < shapes.size(); ++k)
      EXPECT_NE(description.find(shapes[k] + " " + paths[k]), std::string::npos) << description;
    EXPECT_GT(drawn.at("focal_baseline_px_m").get<double>(), 0.0);
    // The lead over the obstacles entering the horizon in view is a minimum over a subset of
    // those of lead_s: never below it, and only where there are such obstacles.
    const int entering = scene.at("entering").get<int>();
    entering_scenes += entering > 0;
    if (!scene.at("lead_entering_s").is_null()) {
      EXPECT_GT(entering, 0);
      ASSERT_FALSE(scene.at("lead_s").is_null());
      EXPECT_GE(scene.at("lead_entering_s").get<double>(), scene.at("lead_s").get<double>());
    }
  }
  EXPECT_EQ(s.at("lead_entering_s").at("count").get<int>() + s.at("missed_entering").get<int>(),
            entering_scenes);
}

TEST_F(CliRandom, BadArgumentsAreOneLineAndStatus2) {
  expect_user_error(run("eval --suite random --count 0 --seed 1"), "count=0");
  expect_user_error(run("eval --suite random --count -3 --seed 1"), "count=-3");
  expect_user_error(run("eval --suite other --count 2 --seed 1"), "suite=other");
  expect_user_error(run("eval --suite random --seed 1"), "--count");
  expect_user_error(run("eval --suite random --count 2"), "--seed");
  expect_user_error(run("eval --suite random --count 2 --seed 1 --max-size 10"), "max-size=10");
  expect_user_error(run("eval --count 2 --seed 1"), "--suite random");
  expect_user_error(run("simulate --random --out d"), "--random needs --seed");
  expect_user_error(run("simulate --seed 3 --scenario head-on --out d"), "--seed needs --random");
  expect_user_error(run("simulate --out d"), "--scenario");
}

}  // namespace
