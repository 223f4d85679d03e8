// Procedural scenes: determinism, variety, and every draw inside the documented table.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "sg/core/error.hpp"
#include "sg/sim/random_scene.hpp"
#include "sg/sim/renderer.hpp"

namespace sg::sim {
namespace {

constexpr double kDeg = CV_PI / 180.0;

bool within(double v, const SampleRange& r, double slack = 1e-9) {
  return v >= r.lo - slack && v <= r.hi + slack;
}

TEST(RandomScene, SameSeedGivesTheSameScenarioAndFrames) {
  const Scenario a = random_scenario(1234), b = random_scenario(1234);
  EXPECT_EQ(to_yaml(a), to_yaml(b));
  Scenario small = a;
  cap_scenario(small, {160, 120}, 3);
  const Renderer ra(small), rb(small);
  for (int i : {0, 2}) {
    const RenderedFrame fa = ra.render(i), fb = rb.render(i);
    EXPECT_EQ(cv::norm(fa.frame.left, fb.frame.left, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(fa.frame.right, fb.frame.right, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(fa.maps.disparity, fb.maps.disparity, cv::NORM_INF), 0.0);
  }
}

TEST(RandomScene, DifferentSeedsDiffer) {
  std::set<std::string> texts;
  for (std::uint32_t seed = 0; seed < 50; ++seed) texts.insert(to_yaml(random_scenario(seed)));
  EXPECT_EQ(texts.size(), 50u);
}

TEST(RandomScene, EveryDrawLiesInItsRangeAndTheSceneIsValid) {
  const RandomSceneRanges& r = kRandomSceneRanges;
  std::set<std::string> platforms, shapes, paths, motions;
  int with_jpeg = 0, clear = 0, with_shadows = 0, ended_at_contact = 0;
  std::set<TextureKind> textures;
  for (std::uint32_t seed = 1000; seed < 1500; ++seed) {
    RandomSceneInfo info;
    const Scenario s = random_scenario(seed, &info);
    SCOPED_TRACE("seed " + std::to_string(seed));
    ASSERT_TRUE(validate(s).empty()) << validate(s).front();
    const core::Camera& c = s.camera;
    EXPECT_TRUE(std::any_of(kRandomImageSizes.begin(), kRandomImageSizes.end(),
                            [&](const auto& wh) { return wh[0] == c.width && wh[1] == c.height; }));
    EXPECT_TRUE(within(2.0 * std::atan(0.5 * c.width / c.focal_px) / kDeg, r.fov_deg, 1e-6));
    EXPECT_TRUE(within(c.baseline_m, r.baseline_m));
    EXPECT_TRUE(within(c.fps, r.fps));
    // The drawn length, or shorter where an obstacle touches the platform (its last frame).
    EXPECT_LE(s.frames / c.fps, r.duration_s.hi + 1.0 / c.fps);
    if (s.frames / c.fps < r.duration_s.lo - 1.0 / c.fps) {
      const double last = (s.frames - 1) / c.fps;
      EXPECT_TRUE(std::any_of(s.obstacles.begin(), s.obstacles.end(), [&](const Box& b) {
        const core::ObstacleTruth o = box_collision(s, b, last);
        return o.colliding && o.ttc_s && *o.ttc_s == 0.0;
      }));
      ++ended_at_contact;
    }
    const auto p =
        static_cast<std::size_t>(std::find_if(kRandomPlatforms.begin(), kRandomPlatforms.end(),
                                              [&](const char* n) { return info.platform == n; }) -
                                 kRandomPlatforms.begin());
    ASSERT_LT(p, kRandomPlatforms.size());
    EXPECT_EQ(s.platform, info.platform);
    EXPECT_TRUE(within(s.height_m, r.height_m[p]));
    const double speed = s.ego_velocity_mps[2];
    if (info.ego_motion == "still") {
      EXPECT_EQ(speed, 0.0);
    }
    if (info.ego_motion == "forward") {
      EXPECT_TRUE(within(speed, r.ego_speed_mps[p]));
    }
    if (info.ego_motion == "accelerating") {
      // Reaches its full speed after the ramp, from a share of it.
      const double full = ego_velocity(s, r.speed_ramp_s.hi + 0.1)[2];
      EXPECT_TRUE(within(full, r.ego_speed_mps[p]));
      EXPECT_LE(speed, r.start_speed_share.hi * full + 1e-9);
    } else if (info.ego_motion == "stopping") {
      EXPECT_TRUE(within(speed, r.ego_speed_mps[p]));
      // Brakes within the drawn length (the scene may end sooner, at a contact) to a standstill.
      ASSERT_EQ(s.ego_accelerations.size(), 2u);
      const double stopped_s = s.ego_accelerations.back().from_s;
      EXPECT_LE(stopped_s, r.duration_s.hi * r.brake_start_share.hi + r.brake_ramp_s.hi);
      EXPECT_NEAR(ego_velocity(s, stopped_s + 1e-6)[2], 0.0, 1e-9);
    } else {
      EXPECT_TRUE(s.ego_accelerations.empty());
    }
    EXPECT_TRUE(within(s.camera_motion.pitch_deg, r.pitch_deg));
    EXPECT_TRUE(within(s.camera_motion.roll_deg, r.roll_deg));
    EXPECT_TRUE(within(s.effects.exposure_time_s * 1e3, r.exposure_time_ms));
    EXPECT_LE(s.effects.exposure_time_s, 0.9 / c.fps + 1e-12);
    textures.insert(s.ground_texture);
    textures.insert(s.background_texture);
    EXPECT_LE(static_cast<int>(s.shadows.casters.size()), r.max_shadow_casters);
    with_shadows += s.shadows.casters.empty() ? 0 : 1;
    for (const ShadowCaster& caster : s.shadows.casters) {
      EXPECT_TRUE(within(caster.radius_m, r.caster_radius_m));
      EXPECT_TRUE(within(caster.darkness, r.shadow_darkness));
      EXPECT_TRUE(within(s.height_m - caster.position_m[1], r.caster_height_m, 1e-6));
    }
    if (info.ego_motion == "turning") {
      EXPECT_TRUE(within(std::abs(s.camera_motion.yaw_rate_dps), r.yaw_rate_dps));
      EXPECT_TRUE(within(speed, {0.0, r.ego_speed_mps[p].hi}));
    } else {
      EXPECT_EQ(s.camera_motion.yaw_rate_dps, 0.0);
    }
    EXPECT_TRUE(within(s.camera_motion.pitch_amplitude_deg, r.pitch_amplitude_deg));
    EXPECT_TRUE(within(s.camera_motion.roll_amplitude_deg, r.roll_amplitude_deg));
    EXPECT_TRUE(within(s.camera_motion.oscillation_hz, r.sway_hz));
    EXPECT_TRUE(within(s.noise_sigma, r.noise_sigma));
    EXPECT_TRUE(within(s.right_gain, r.right_gain));
    EXPECT_TRUE(within(s.effects.right_shift_y_px, r.right_shift_y_px));
    EXPECT_TRUE(within(s.effects.vignetting, r.vignetting));
    EXPECT_LE(static_cast<int>(s.effects.exposure_steps.size()), r.max_exposure_steps);
    for (const ExposureStep& step : s.effects.exposure_steps) {
      EXPECT_TRUE(within(step.gain, r.exposure_gain));
      EXPECT_TRUE(within(step.from_s, {0.0, r.duration_s.hi}));
    }
    if (s.effects.jpeg_quality != 0) {
      ++with_jpeg;
      EXPECT_TRUE(within(s.effects.jpeg_quality, r.jpeg_quality, 0.5));
    }
    EXPECT_GE(s.background_z_m, r.background_z_m.lo);
    EXPECT_LE(static_cast<int>(s.obstacles.size()), r.max_obstacles);
    ASSERT_EQ(info.shapes.size(), s.obstacles.size());
    for (std::size_t i = 0; i < s.obstacles.size(); ++i) {
      const auto shape = static_cast<std::size_t>(
          std::find_if(kRandomShapes.begin(), kRandomShapes.end(),
                       [&](const char* n) { return info.shapes[i] == n; }) -
          kRandomShapes.begin());
      ASSERT_LT(shape, kRandomShapes.size());
      for (int a = 0; a < 3; ++a)
        EXPECT_TRUE(
            within(s.obstacles[i].size_m[a], r.shape_size_m[shape][static_cast<std::size_t>(a)]));
      const double k = info.start_ttc_over_horizon[i];
      EXPECT_TRUE(within(k, r.start_inside_horizon) || within(k, r.start_outside_horizon));
      EXPECT_TRUE(within(cv::norm(s.obstacles[i].velocity_mps),
                         {0.0, r.obstacle_speed_mps[p].hi + r.ego_speed_mps[p].hi}));
      EXPECT_LT(s.obstacles[i].position_m[2] + 0.5 * s.obstacles[i].size_m[2], s.background_z_m);
      shapes.insert(info.shapes[i]);
      textures.insert(s.obstacles[i].texture);
      paths.insert(info.paths[i]);
    }
    clear += s.obstacles.empty() ? 1 : 0;
    platforms.insert(info.platform);
    motions.insert(info.ego_motion);
  }
  // Every kind is drawn over 500 seeds.
  EXPECT_EQ(platforms.size(), kRandomPlatforms.size());
  EXPECT_EQ(shapes.size(), kRandomShapes.size());
  EXPECT_EQ(paths.size(), kRandomPaths.size());
  EXPECT_EQ(motions.size(), kRandomEgoMotions.size());
  EXPECT_EQ(textures.size(), texture_kind_names().size());
  EXPECT_GT(with_jpeg, 150);
  EXPECT_GT(with_shadows, 120);
  EXPECT_GT(clear, 50);
  EXPECT_GT(ended_at_contact, 50);
}

// Solid obstacles never pass through each other: at every frame of every scene, each pair is
// apart along some axis. Their ids stay 1..n, in the order the description lists them.
TEST(RandomScene, NoTwoObstaclesOverlapAtAnyFrame) {
  int pairs = 0, four = 0;
  for (std::uint32_t seed = 1000; seed < 1500; ++seed) {
    RandomSceneInfo info;
    const Scenario s = random_scenario(seed, &info);
    SCOPED_TRACE("seed " + std::to_string(seed));
    ASSERT_EQ(info.shapes.size(), s.obstacles.size());
    four += s.obstacles.size() == 4 ? 1 : 0;
    for (std::size_t i = 0; i < s.obstacles.size(); ++i) {
      EXPECT_EQ(s.obstacles[i].id, static_cast<int>(i) + 1);
      for (std::size_t j = 0; j < i; ++j) {
        const Box &a = s.obstacles[i], &b = s.obstacles[j];
        ++pairs;
        for (int f = 0; f < s.frames; ++f) {
          const double t = f / s.camera.fps;
          const cv::Vec3d gap = box_position(a, t) - box_position(b, t);
          const bool apart = std::abs(gap[0]) >= 0.5 * (a.size_m[0] + b.size_m[0]) ||
                             std::abs(gap[1]) >= 0.5 * (a.size_m[1] + b.size_m[1]) ||
                             std::abs(gap[2]) >= 0.5 * (a.size_m[2] + b.size_m[2]);
          ASSERT_TRUE(apart) << "obstacles " << a.id << " and " << b.id << " meet at frame " << f;
        }
      }
    }
  }
  // Scenes still hold several obstacles: 0-4 are drawn, and only those that would meet go.
  EXPECT_GT(pairs, 300);
  EXPECT_GT(four, 10);
}

TEST(RandomScene, ATurningCarDrivesAnArcACarCanDrive) {
  // Seed 1051 used to turn a car on a 2.4-m radius at 0.9 m/s.
  const RandomSceneRanges& r = kRandomSceneRanges;
  int turning_cars = 0;
  double tightest_m = 1e9, hardest_mps2 = 0.0;
  for (std::uint32_t seed = 1000; seed < 2000; ++seed) {
    RandomSceneInfo info;
    const Scenario s = random_scenario(seed, &info);
    if (s.platform != "car" || info.ego_motion != "turning") continue;
    ++turning_cars;
    const double yaw_rps = std::abs(s.camera_motion.yaw_rate_dps) * kDeg;
    const double speed = s.ego_velocity_mps[2];
    tightest_m = std::min(tightest_m, speed / yaw_rps);
    hardest_mps2 = std::max(hardest_mps2, speed * yaw_rps);
    EXPECT_LE(speed, r.ego_speed_mps[2].hi) << seed;
  }
  EXPECT_GT(turning_cars, 20);
  EXPECT_GE(tightest_m, r.car_min_turn_radius_m - 1e-9);
  EXPECT_LE(hardest_mps2, r.car_max_lateral_mps2 + 1e-9);
  // The bounds are reached, not just respected: the speeds span them.
  EXPECT_LT(tightest_m, 1.2 * r.car_min_turn_radius_m);
  EXPECT_GT(hardest_mps2, 0.8 * r.car_max_lateral_mps2);
}

TEST(RandomScene, CapKeepsTheFieldOfViewAndShortens) {
  Scenario s = random_scenario(7);
  const double fov = std::atan(0.5 * s.camera.width / s.camera.focal_px);
  cap_scenario(s, {320, 240}, 10);
  EXPECT_LE(s.camera.width, 320);
  EXPECT_LE(s.camera.height, 240);
  EXPECT_LE(s.frames, 10);
  EXPECT_NEAR(std::atan(0.5 * s.camera.width / s.camera.focal_px), fov, 0.01);
  EXPECT_TRUE(validate(s).empty());
}

TEST(RandomScene, ScenarioFileNamesARandomSceneAndOverridesFields) {
  const auto path = std::filesystem::temp_directory_path() / "sg_random_scene_test.yaml";
  {
    std::ofstream out(path);
    out << "random: {seed: 42}\nframes: 5\nnoise_sigma: 0\n";
  }
  const Scenario s = load_scenario_file(path.string());
  Scenario expected = random_scenario(42);
  expected.frames = 5;
  expected.noise_sigma = 0;
  EXPECT_EQ(to_yaml(s), to_yaml(expected));
  {
    std::ofstream out(path);
    out << "random: {seed: -1}\n";
  }
  EXPECT_THROW(load_scenario_file(path.string()), core::InputError);
  std::filesystem::remove(path);
}

TEST(RandomScene, EffectsRoundTripThroughYaml) {
  Scenario s = random_scenario(3);
  s.effects.exposure_steps = {{0.5, 1.2}, {1.0, 0.8}};
  s.effects.jpeg_quality = 70;
  s.effects.right_shift_y_px = 0.25;
  s.effects.vignetting = 0.3;
  const auto path = std::filesystem::temp_directory_path() / "sg_random_effects_test.yaml";
  save_scenario_file(s, path.string());
  EXPECT_EQ(to_yaml(load_scenario_file(path.string())), to_yaml(s));
  std::filesystem::remove(path);
}

TEST(RandomScene, EffectsChangeTheImagesButNotTheTruth) {
  Scenario plain = random_scenario(11);
  cap_scenario(plain, {160, 120}, 3);
  plain.effects = ImageEffects{};
  Scenario changed = plain;
  changed.effects.exposure_steps = {{0.0, 1.3}};
  changed.effects.vignetting = 0.4;
  changed.effects.right_shift_y_px = 0.5;
  changed.effects.jpeg_quality = 50;
  const RenderedFrame a = Renderer(plain).render(1), b = Renderer(changed).render(1);
  EXPECT_GT(cv::norm(a.frame.left, b.frame.left, cv::NORM_L1), 0.0);
  EXPECT_GT(cv::norm(a.frame.right, b.frame.right, cv::NORM_L1), 0.0);
  EXPECT_EQ(cv::norm(a.maps.disparity, b.maps.disparity, cv::NORM_INF), 0.0);
  EXPECT_EQ(a.truth.alarm, b.truth.alarm);
}

}  // namespace
}  // namespace sg::sim
