#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>

#include "sg/core/error.hpp"
#include "sg/core/platform.hpp"
#include "sg/sim/scenario.hpp"

namespace sg::sim {
namespace {

namespace fs = std::filesystem;

bool mentions(const std::vector<std::string>& problems, const std::string& text) {
  for (const auto& p : problems)
    if (p.find(text) != std::string::npos) return true;
  return false;
}

/// Writes `text` to a fresh file in the test temp dir and returns its path.
std::string write_file(const std::string& name, const std::string& text) {
  const fs::path dir = fs::path(::testing::TempDir()) / "sg_sim_scenario_test";
  fs::create_directories(dir);
  const fs::path path = dir / name;
  std::ofstream(path) << text;
  return path.string();
}

/// The InputError message of load_scenario_file(path), or "" when it does not throw.
std::string load_error(const std::string& path) {
  try {
    load_scenario_file(path);
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Scenario, BuiltinsIncludeTheRequiredOnesAndValidate) {
  const auto names = builtin_scenario_names();
  const std::set<std::string> have(names.begin(), names.end());
  for (const char* required :
       {"head-on", "crossing", "receding", "static", "ego-wall", "ego-pass", "two-obstacles",
        "thin-pole", "overhang", "turning", "car-stopped", "car-cut-in", "cold-start"})
    EXPECT_TRUE(have.count(required)) << required;
  for (const auto& name : names) {
    const Scenario s = builtin_scenario(name);
    EXPECT_EQ(s.name, name);
    EXPECT_FALSE(s.description.empty()) << name;
    EXPECT_FALSE(s.obstacles.empty()) << name;
    EXPECT_TRUE(validate(s).empty()) << name << ": " << validate(s).front();
    EXPECT_DOUBLE_EQ(s.envelope.horizon_s, 3.0);
    if (!s.platform.empty()) {
      // Platform scenarios use their platform's envelope for the ground truth.
      const core::Envelope e = core::platform_envelope(s.platform);
      EXPECT_EQ(s.envelope.half_width_m, e.half_width_m) << name;
      EXPECT_EQ(s.envelope.z_contact_m, e.z_contact_m) << name;
      continue;
    }
    // Every other built-in uses the default camera and envelope.
    EXPECT_EQ(s.camera.width, 640);
    EXPECT_EQ(s.camera.height, 480);
    EXPECT_DOUBLE_EQ(s.camera.focal_px, 500.0);
    EXPECT_DOUBLE_EQ(s.camera.baseline_m, 0.12);
    EXPECT_DOUBLE_EQ(s.height_m, 1.2);
    EXPECT_DOUBLE_EQ(s.envelope.horizon_s, 3.0);
  }
}

TEST(Scenario, UnknownNameListsTheBuiltins) {
  try {
    resolve_scenario("no-such-scenario");
    FAIL() << "expected InputError";
  } catch (const core::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no-such-scenario"), std::string::npos) << what;
    for (const auto& name : builtin_scenario_names())
      EXPECT_NE(what.find(name), std::string::npos) << what;
  }
  EXPECT_THROW(builtin_scenario("nope"), core::InputError);
}

TEST(Scenario, ResolveAcceptsBuiltinNamesAndFiles) {
  EXPECT_EQ(resolve_scenario("crossing").name, "crossing");
  const std::string path = write_file("resolve.yaml", "name: mine\nframes: 5\n");
  const Scenario s = resolve_scenario(path);
  EXPECT_EQ(s.name, "mine");
  EXPECT_EQ(s.frames, 5);
}

TEST(Scenario, ValidateNamesEachBadField) {
  Scenario s = builtin_scenario("static");
  s.frames = 1;
  s.camera.focal_px = -1;
  s.background_z_m = 0;
  s.noise_sigma = -0.5;
  s.right_gain = 0;
  s.edge_samples = 9;
  s.obstacles[1].id = s.obstacles[0].id;
  s.obstacles[2].id = 0;
  s.obstacles[3].size_m[2] = 0;
  s.envelope.horizon_s = 0;
  const auto problems = validate(s);
  EXPECT_TRUE(mentions(problems, "frames=1")) << problems.size();
  EXPECT_TRUE(mentions(problems, "camera.focal_px=-1"));
  EXPECT_TRUE(mentions(problems, "background_z_m=0"));
  EXPECT_TRUE(mentions(problems, "noise_sigma=-0.5"));
  EXPECT_TRUE(mentions(problems, "right_gain=0"));
  EXPECT_TRUE(mentions(problems, "edge_samples=9: must be in 1..8"));
  EXPECT_TRUE(mentions(problems, "obstacles[1].id=1: must be unique"));
  EXPECT_TRUE(mentions(problems, "obstacles[2].id=0"));
  EXPECT_TRUE(mentions(problems, "obstacles[3].size_m"));
  EXPECT_TRUE(mentions(problems, "envelope.horizon_s=0"));
}

TEST(Scenario, YamlRoundTripKeepsEveryField) {
  Scenario s = builtin_scenario("two-obstacles");
  s.description = "a \"quoted\": description";
  s.camera = {161, 121, 125.25, 0.1, 80.5, 60.0, 25.0};
  s.height_m = 1.5;
  s.ego_velocity_mps = {0.1, -0.2, 1.75};
  s.background_z_m = 33.3;
  s.background_height_m = 7.5;
  s.ground_seed = 4000000000U;
  s.background_seed = 5;
  s.noise_sigma = 0.7;
  s.right_gain = 0.9;
  s.noise_seed = 99;
  s.edge_samples = 2;
  s.envelope = {0.6, -0.9, 0.8, 0.4, 2.5};
  s.min_area_px = 77;
  s.obstacles[1].texture_seed = 1234;
  s.camera_motion = {12.5, 2.0, -1.5, 1.75, -4.5, 2.25};
  s.platform = "drone";
  s.ego_follows_heading = true;
  s.obstacles[0].accelerations = {{0.5, {1.0, 0.0, -2.0}}, {1.25, {0, 0, 0}}};
  s.ego_accelerations = {{0.25, {0.0, 0.0, -1.5}}, {1.5, {0, 0, 0}}};
  s.obstacles[1].texture = TextureKind::kClutter;
  s.ground_texture = TextureKind::kTiles;
  s.background_texture = TextureKind::kStripes;
  s.shadows.to_light = {0.25, -0.75, 0.5};
  s.shadows.casters = {{{1.0, -3.0, 9.0}, {0.5, 0.0, -0.25}, 1.5, 0.625}};
  s.effects.exposure_time_s = 0.0125;
  const std::string path = write_file("roundtrip.yaml", "");
  save_scenario_file(s, path);
  const Scenario r = load_scenario_file(path);
  EXPECT_EQ(r.name, s.name);
  EXPECT_EQ(r.description, s.description);
  EXPECT_EQ(r.camera_motion.yaw_rate_dps, 12.5);
  EXPECT_EQ(r.camera_motion.pitch_amplitude_deg, 2.0);
  EXPECT_EQ(r.camera_motion.roll_amplitude_deg, -1.5);
  EXPECT_EQ(r.camera_motion.oscillation_hz, 1.75);
  EXPECT_EQ(r.camera_motion.pitch_deg, -4.5);
  EXPECT_EQ(r.camera_motion.roll_deg, 2.25);
  EXPECT_EQ(r.platform, "drone");
  ASSERT_EQ(r.ego_accelerations.size(), 2u);
  EXPECT_EQ(r.ego_accelerations[0].from_s, 0.25);
  EXPECT_EQ(r.ego_accelerations[0].acceleration_mps2, cv::Vec3d(0.0, 0.0, -1.5));
  EXPECT_EQ(r.obstacles[0].texture, TextureKind::kNoise);
  EXPECT_EQ(r.obstacles[1].texture, TextureKind::kClutter);
  EXPECT_EQ(r.ground_texture, TextureKind::kTiles);
  EXPECT_EQ(r.background_texture, TextureKind::kStripes);
  EXPECT_EQ(r.shadows.to_light, cv::Vec3d(0.25, -0.75, 0.5));
  ASSERT_EQ(r.shadows.casters.size(), 1u);
  EXPECT_EQ(r.shadows.casters[0].position_m, cv::Vec3d(1.0, -3.0, 9.0));
  EXPECT_EQ(r.shadows.casters[0].velocity_mps, cv::Vec3d(0.5, 0.0, -0.25));
  EXPECT_EQ(r.shadows.casters[0].radius_m, 1.5);
  EXPECT_EQ(r.shadows.casters[0].darkness, 0.625);
  EXPECT_EQ(r.effects.exposure_time_s, 0.0125);
  EXPECT_EQ(to_yaml(r), to_yaml(s));
  EXPECT_TRUE(r.ego_follows_heading);
  ASSERT_EQ(r.obstacles[0].accelerations.size(), 2u);
  EXPECT_EQ(r.obstacles[0].accelerations[0].from_s, 0.5);
  EXPECT_EQ(r.obstacles[0].accelerations[0].acceleration_mps2, cv::Vec3d(1.0, 0.0, -2.0));
  EXPECT_EQ(r.obstacles[0].accelerations[1].from_s, 1.25);
  EXPECT_TRUE(r.obstacles[1].accelerations.empty());
  EXPECT_EQ(r.frames, s.frames);
  EXPECT_EQ(r.camera.width, 161);
  EXPECT_EQ(r.camera.height, 121);
  EXPECT_EQ(r.camera.focal_px, 125.25);
  EXPECT_EQ(r.camera.baseline_m, 0.1);
  EXPECT_EQ(r.camera.cx, 80.5);
  EXPECT_EQ(r.camera.cy, 60.0);
  EXPECT_EQ(r.camera.fps, 25.0);
  EXPECT_EQ(r.height_m, 1.5);
  EXPECT_EQ(r.ego_velocity_mps, s.ego_velocity_mps);
  EXPECT_EQ(r.background_z_m, 33.3);
  EXPECT_EQ(r.background_height_m, 7.5);
  EXPECT_EQ(r.ground_seed, 4000000000U);
  EXPECT_EQ(r.background_seed, 5U);
  EXPECT_EQ(r.noise_sigma, 0.7);
  EXPECT_EQ(r.right_gain, 0.9);
  EXPECT_EQ(r.noise_seed, 99U);
  EXPECT_EQ(r.edge_samples, 2);
  EXPECT_EQ(r.envelope.half_width_m, 0.6);
  EXPECT_EQ(r.envelope.y_top_m, -0.9);
  EXPECT_EQ(r.envelope.y_bottom_m, 0.8);
  EXPECT_EQ(r.envelope.z_contact_m, 0.4);
  EXPECT_EQ(r.envelope.horizon_s, 2.5);
  EXPECT_EQ(r.min_area_px, 77);
  ASSERT_EQ(r.obstacles.size(), s.obstacles.size());
  for (std::size_t i = 0; i < s.obstacles.size(); ++i) {
    EXPECT_EQ(r.obstacles[i].id, s.obstacles[i].id);
    EXPECT_EQ(r.obstacles[i].size_m, s.obstacles[i].size_m);
    EXPECT_EQ(r.obstacles[i].position_m, s.obstacles[i].position_m);
    EXPECT_EQ(r.obstacles[i].velocity_mps, s.obstacles[i].velocity_mps);
    EXPECT_EQ(r.obstacles[i].texture_seed, s.obstacles[i].texture_seed);
  }
}

TEST(Scenario, SmallFileKeepsDefaultsAndJsonWorks) {
  const std::string yaml = write_file("small.yaml",
                                      "frames: 10\n"
                                      "obstacles:\n"
                                      "  - id: 3\n"
                                      "    position_m: [0.5, 0.45, 8]\n"
                                      "    velocity_mps: [0, 0, -2]\n");
  const Scenario s = load_scenario_file(yaml);
  EXPECT_EQ(s.name, "small");  // the file stem when no name is given
  EXPECT_EQ(s.frames, 10);
  EXPECT_EQ(s.camera.width, 640);
  EXPECT_DOUBLE_EQ(s.background_z_m, 40.0);
  ASSERT_EQ(s.obstacles.size(), 1u);
  EXPECT_EQ(s.obstacles[0].id, 3);
  EXPECT_EQ(s.obstacles[0].size_m, cv::Vec3d(1.0, 1.5, 0.5));
  EXPECT_EQ(s.obstacles[0].position_m, cv::Vec3d(0.5, 0.45, 8));

  const std::string json = write_file(
      "small.json",
      R"({"name": "j", "frames": 4, "camera": {"width": 99}, "ego_velocity_mps": [0, 0, 1],
          "obstacles": [{"id": 2, "size_m": [1, 2, 3]}]})");
  const Scenario j = load_scenario_file(json);
  EXPECT_EQ(j.name, "j");
  EXPECT_EQ(j.camera.width, 99);
  EXPECT_EQ(j.ego_velocity_mps, cv::Vec3d(0, 0, 1));
  ASSERT_EQ(j.obstacles.size(), 1u);
  EXPECT_EQ(j.obstacles[0].size_m, cv::Vec3d(1, 2, 3));
}

TEST(Scenario, BadFilesNameTheFileAndField) {
  struct Case {
    const char* file;
    const char* text;
    const char* field;  // must appear in the message, besides the file name
  };
  const Case cases[] = {
      {"syntax.yaml", "frames: [1, 2\nname: x\n", "syntax"},
      {"type.yaml", "camera:\n  focal_px: abc\n", "camera.focal_px"},
      {"int.yaml", "frames: 2.5\n", "frames"},
      {"unknown.yaml", "frames: 10\ncolour: red\n", "colour"},
      {"nested.yaml", "envelope:\n  widht: 1\n", "envelope.widht"},
      {"vec.yaml", "ego_velocity_mps: [1, 2]\n", "ego_velocity_mps"},
      {"seed.yaml", "noise_seed: -3\n", "noise_seed"},
      {"bool.yaml", "ego_follows_heading: sometimes\n", "ego_follows_heading"},
      {"box.yaml", "obstacles:\n  - id: 1\n    size_m: [1, x, 1]\n", "obstacles[0].size_m[1]"},
      {"list.yaml", "obstacles: 3\n", "obstacles"},
      {"notmap.yaml", "- 1\n- 2\n", "expected a mapping"},
      {"frames.yaml", "frames: 1\n", "frames=1"},
      {"dup.yaml", "obstacles:\n  - id: 2\n  - id: 2\n", "obstacles[1].id=2"},
      {"empty.yaml", "", "empty"},
      {"texture.yaml", "ground_texture: marble\n", "ground_texture"},
      {"shadow.yaml", "shadows:\n  casters:\n    - {darkness: 2}\n", "shadows.casters[0].darkness=2"},
      {"light.yaml", "shadows:\n  to_light: [0, 1, 0]\n", "shadows.to_light"},
      {"blur.yaml", "effects: {exposure_time_s: 0.5}\n", "effects.exposure_time_s=0.5"},
      {"ego.yaml", "ego_accelerations:\n  - {from_s: -1}\n", "ego_accelerations[0].from_s=-1"},
  };
  for (const Case& c : cases) {
    const std::string path = write_file(c.file, c.text);
    const std::string what = load_error(path);
    EXPECT_NE(what.find(path), std::string::npos) << c.file << ": " << what;
    EXPECT_NE(what.find(c.field), std::string::npos) << c.file << ": " << what;
  }
  // Flow collections nested more than 32 levels are refused before yaml-cpp recurses into them.
  const std::string deep =
      write_file("deep.yaml", "obstacles: " + std::string(33, '[') + std::string(33, ']') + "\n");
  EXPECT_NE(load_error(deep).find(deep + ": collections ([ ] or { }) nested more than 32"),
            std::string::npos)
      << load_error(deep);
  const std::string missing = (fs::path(::testing::TempDir()) / "missing_sg.yaml").string();
  const std::string what = load_error(missing);
  EXPECT_NE(what.find(missing), std::string::npos) << what;
  EXPECT_NE(what.find("not found"), std::string::npos) << what;
}

}  // namespace
}  // namespace sg::sim
