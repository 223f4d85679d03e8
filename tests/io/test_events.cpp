#include <gtest/gtest.h>

#include <fstream>
#include <set>

#include "io_test_util.hpp"
#include "sg/io/events.hpp"

namespace sg::io {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing_util::input_error_of;
using testing_util::ScratchDir;

core::Detection sample_detection() {
  core::Detection d;
  d.frame = 17;
  d.time_s = 1.23456789;
  d.signal = true;
  d.severity = core::Severity::kDanger;
  d.steering = core::Steering::kLeft;
  d.regions = {{"left", false, 0}, {"centre", true, 812}, {"right", false, 40}};
  core::Obstacle a;
  a.bbox = cv::Rect(10, 20, 31, 17);
  a.pixels = 400;
  a.distance_m = 4.2000049;
  a.ttc_s = 1.333333;
  a.velocity = cv::Vec3d(0.1, -0.00004, -3.14159);
  core::Obstacle b;
  b.bbox = cv::Rect(50, 5, 7, 9);
  b.pixels = 160;
  b.distance_m = 9.87654;
  d.obstacles = {a, b};
  d.latency_ms = 12.34567;
  return d;
}

std::set<std::string> keys(const json& j) {
  std::set<std::string> out;
  for (auto it = j.begin(); it != j.end(); ++it) out.insert(it.key());
  return out;
}

TEST(Events, KeysAndValues) {
  const json j = detection_to_json(sample_detection(), true);
  EXPECT_EQ(keys(j), (std::set<std::string>{"frame", "time_s", "signal", "severity", "steering",
                                            "regions", "obstacles", "latency_ms"}));
  EXPECT_EQ(j["frame"], 17);
  EXPECT_DOUBLE_EQ(j["time_s"].get<double>(), 1.2346);
  EXPECT_EQ(j["signal"], true);
  EXPECT_EQ(j["severity"], "danger");
  EXPECT_EQ(j["steering"], "left");
  ASSERT_EQ(j["regions"].size(), 3u);
  EXPECT_EQ(keys(j["regions"][1]), (std::set<std::string>{"name", "fired", "dangerous_px"}));
  EXPECT_EQ(j["regions"][1]["name"], "centre");
  EXPECT_EQ(j["regions"][1]["fired"], true);
  EXPECT_EQ(j["regions"][1]["dangerous_px"], 812);
  EXPECT_EQ(j["regions"][0]["fired"], false);

  ASSERT_EQ(j["obstacles"].size(), 2u);
  const json& a = j["obstacles"][0];
  EXPECT_EQ(keys(a),
            (std::set<std::string>{"bbox", "pixels", "distance_m", "ttc_s", "velocity_mps"}));
  EXPECT_EQ(a["bbox"], json({10, 20, 31, 17}));
  EXPECT_EQ(a["pixels"], 400);
  EXPECT_DOUBLE_EQ(a["distance_m"].get<double>(), 4.2);
  EXPECT_DOUBLE_EQ(a["ttc_s"].get<double>(), 1.3333);
  ASSERT_EQ(a["velocity_mps"].size(), 3u);
  EXPECT_DOUBLE_EQ(a["velocity_mps"][0].get<double>(), 0.1);
  EXPECT_DOUBLE_EQ(a["velocity_mps"][2].get<double>(), -3.1416);

  const json& b = j["obstacles"][1];
  EXPECT_EQ(keys(b), (std::set<std::string>{"bbox", "pixels", "distance_m", "ttc_s"}));
  EXPECT_TRUE(b["ttc_s"].is_null());
  EXPECT_DOUBLE_EQ(b["distance_m"].get<double>(), 9.8765);

  EXPECT_DOUBLE_EQ(j["latency_ms"].get<double>(), 12.346);
}

TEST(Events, RoundedNumbersPrintShort) {
  const std::string text = detection_to_json(sample_detection(), false).dump();
  EXPECT_NE(text.find("\"time_s\":1.2346"), std::string::npos) << text;
  EXPECT_NE(text.find("\"distance_m\":4.2,"), std::string::npos) << text;
  EXPECT_NE(text.find("\"velocity_mps\":[0.1,0.0,-3.1416]"), std::string::npos) << text;
}

TEST(Events, TimingFalseOmitsLatency) {
  const json j = detection_to_json(sample_detection(), false);
  EXPECT_FALSE(j.contains("latency_ms"));
  EXPECT_TRUE(detection_to_json(sample_detection(), true).contains("latency_ms"));
}

TEST(Events, EmptyDetection) {
  const json j = detection_to_json(core::Detection{}, false);
  EXPECT_TRUE(j["regions"].is_array() && j["regions"].empty());
  EXPECT_TRUE(j["obstacles"].is_array() && j["obstacles"].empty());
  EXPECT_EQ(j["severity"], "none");
  EXPECT_EQ(j["steering"], "straight");
}

TEST(EventWriter, OneParsableLinePerWriteAndDeterministic) {
  ScratchDir tmp;
  const core::Detection d = sample_detection();
  core::Detection d2 = d;
  d2.frame = 18;
  d2.obstacles.clear();
  d2.signal = false;
  for (const char* name : {"a.jsonl", "b.jsonl"}) {
    EventWriter w(tmp.path() / name, false);
    w.write(d);
    w.write(d2);
    // Flushed: readable while the writer is still open.
    std::ifstream in(tmp.path() / name);
    std::string line;
    int n = 0;
    while (std::getline(in, line)) {
      const json j = json::parse(line);
      EXPECT_EQ(j["frame"], 17 + n);
      ++n;
    }
    EXPECT_EQ(n, 2);
  }
  std::ifstream a(tmp.path() / "a.jsonl"), b(tmp.path() / "b.jsonl");
  const std::string sa((std::istreambuf_iterator<char>(a)), {});
  const std::string sb((std::istreambuf_iterator<char>(b)), {});
  EXPECT_FALSE(sa.empty());
  EXPECT_EQ(sa, sb);
  EXPECT_EQ(sa.back(), '\n');
}

TEST(EventWriter, UnwritablePath) {
  ScratchDir tmp;
  const fs::path bad = tmp.path() / "no_such_dir" / "events.jsonl";
  const std::string msg = input_error_of([&] { EventWriter w(bad, false); });
  EXPECT_NE(msg.find(bad.string()), std::string::npos) << msg;
}

}  // namespace
}  // namespace sg::io
