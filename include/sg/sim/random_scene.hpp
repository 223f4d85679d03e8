#pragma once
/// Procedural scenes (docs/random-suite.md): random_scenario(seed) samples a whole Scenario from
/// the ranges of kRandomSceneRanges with a std::mt19937 seeded by `seed`. Same seed, same scene
/// (on one standard library: the distributions are libstdc++'s).
#include <array>
#include <cstdint>
#include <string>

#include "sg/sim/scenario.hpp"

namespace sg::sim {

/// A closed interval [lo, hi] sampled uniformly.
struct SampleRange {
  double lo = 0.0;
  double hi = 0.0;
};

/// The platforms a scene is made for; each names its detector preset (core::platform_names).
inline constexpr std::array<const char*, 4> kRandomPlatforms = {"walker", "robot", "car", "drone"};
/// Obstacle shapes (docs/random-suite.md): sizes in RandomSceneRanges.
inline constexpr std::array<const char*, 6> kRandomShapes = {"box", "pole", "person",
                                                             "bar", "wall", "car"};
/// Obstacle paths relative to the camera.
inline constexpr std::array<const char*, 6> kRandomPaths = {"head-on",   "oblique",  "crossing",
                                                            "near-miss", "receding", "stopped"};
/// Ego motions: "accelerating" starts slower and speeds up, "stopping" brakes to a standstill.
inline constexpr std::array<const char*, 5> kRandomEgoMotions = {"forward", "turning", "still",
                                                                 "accelerating", "stopping"};
/// Image sizes a scene picks from (width x height, px): 320x240 to 1280x720.
inline constexpr std::array<std::array<int, 2>, 6> kRandomImageSizes = {
    {{320, 240}, {424, 240}, {640, 360}, {640, 480}, {848, 480}, {1280, 720}}};

/// Every range a random scene samples from; the single table docs/random-suite.md reproduces.
/// Units in the names; per-platform values indexed like kRandomPlatforms.
struct RandomSceneRanges {
  SampleRange fov_deg{50.0, 100.0};  ///< horizontal field of view; f = (W/2) / tan(fov/2)
  SampleRange baseline_m{0.05, 0.5};
  SampleRange fps{10.0, 60.0};
  SampleRange duration_s{2.5, 5.0};  ///< frames = round(duration * fps), >= 2
  std::array<SampleRange, 4> height_m{{{1.1, 1.6}, {0.3, 1.0}, {1.1, 1.5}, {1.0, 4.0}}};
  std::array<SampleRange, 4> ego_speed_mps{{{0.5, 1.8}, {0.3, 2.0}, {4.0, 20.0}, {1.0, 6.0}}};
  /// Speed of an obstacle along its path (0 for "stopped").
  std::array<SampleRange, 4> obstacle_speed_mps{{{0.3, 2.0}, {0.3, 2.0}, {1.0, 12.0}, {0.3, 3.0}}};
  /// |yaw rate| of a "turning" ego motion (either sign); it keeps 0..1 of its forward speed.
  SampleRange yaw_rate_dps{5.0, 25.0};
  /// A turning car drives an arc a car can drive: its share 0..1 spans the speeds from yaw rate
  /// x car_min_turn_radius_m up to its forward speed or car_max_lateral_mps2 / yaw rate.
  double car_min_turn_radius_m = 5.0;
  double car_max_lateral_mps2 = 4.0;
  /// "accelerating": starts at this share of its speed, reaches the speed after the ramp.
  SampleRange start_speed_share{0.0, 0.5};
  SampleRange speed_ramp_s{1.0, 2.5};
  /// "stopping": brakes from this share of the scene's duration on, over the ramp.
  SampleRange brake_start_share{0.1, 0.6};
  SampleRange brake_ramp_s{0.5, 2.0};
  /// Fixed mounting tilt (positive pitch looks up).
  SampleRange pitch_deg{-5.0, 5.0};
  SampleRange roll_deg{-3.0, 3.0};
  /// Camera sway amplitudes for walker and drone; robot and car sway a third of it.
  SampleRange pitch_amplitude_deg{0.0, 3.0};
  SampleRange roll_amplitude_deg{0.0, 3.0};
  SampleRange sway_hz{0.5, 2.5};
  /// 0..max_obstacles drawn, uniform; one whose box meets an earlier one's is left out.
  int max_obstacles = 4;
  /// Width (X), height (Y), depth (Z) per shape, indexed like kRandomShapes, m.
  std::array<std::array<SampleRange, 3>, 6> shape_size_m{{
      {{{0.3, 1.0}, {0.3, 1.2}, {0.3, 1.0}}},    // box
      {{{0.05, 0.2}, {1.5, 3.0}, {0.05, 0.2}}},  // pole
      {{{0.4, 0.6}, {1.5, 1.9}, {0.25, 0.4}}},   // person
      {{{0.8, 2.5}, {0.05, 0.3}, {0.1, 0.4}}},   // bar (overhanging)
      {{{2.0, 6.0}, {1.5, 3.0}, {0.2, 0.4}}},    // wall
      {{{1.6, 2.0}, {1.4, 1.7}, {3.8, 4.8}}},    // car
  }};
  /// Start of an obstacle, as its time to contact at frame 0 over the horizon: below 1 it starts
  /// inside the horizon, above 1 outside (probability 1/2 each).
  SampleRange start_inside_horizon{0.5, 1.0};
  SampleRange start_outside_horizon{1.05, 2.0};
  SampleRange near_miss_gap_m{0.1, 0.6};      ///< clearance beside the envelope of a near miss
  SampleRange oblique_angle_deg{20.0, 60.0};  ///< oblique path: angle to the optical axis
  SampleRange crossing_gap_m{1.0, 5.0};       ///< crossing: passes this far beyond the contact
  /// Bottom of an overhanging bar above the ground, m.
  SampleRange bar_clearance_m{0.8, 2.0};
  /// Drones meet obstacles at flight level: their centre's Y (camera frame at t = 0), m.
  SampleRange drone_obstacle_y_m{-0.5, 0.5};
  SampleRange background_z_m{15.0, 60.0};
  /// Chance of each texture kind (indexed like sim::texture_kind_names(): noise, low, tiles,
  /// stripes, clutter), drawn for the ground, the background and each obstacle.
  std::array<double, 5> texture_weights{0.4, 0.15, 0.15, 0.15, 0.15};
  // Moving cast shadows: in this share of scenes, 1..max casters.
  double shadow_probability = 0.4;
  int max_shadow_casters = 2;
  SampleRange sun_elevation_deg{25.0, 70.0};  ///< the light's direction, any azimuth
  SampleRange caster_height_m{2.0, 8.0};      ///< above the ground
  SampleRange caster_radius_m{0.5, 3.0};
  SampleRange caster_speed_mps{0.3, 3.0};  ///< horizontal, any direction
  SampleRange shadow_darkness{0.3, 0.7};
  SampleRange shadow_ahead_m{2.0, 20.0};  ///< its shadow starts this far ahead on the ground ...
  SampleRange shadow_side_m{-5.0, 5.0};   ///< ... and this far to the side
  // Light and sensor.
  SampleRange noise_sigma{0.0, 4.0};  ///< gray levels
  SampleRange right_gain{0.85, 1.15};
  SampleRange right_shift_y_px{-0.5, 0.5};
  SampleRange vignetting{0.0, 0.5};
  int max_exposure_steps = 2;           ///< 0..max, at uniform times in the scene
  SampleRange exposure_gain{0.7, 1.3};  ///< gain of each step
  double jpeg_probability = 0.5;        ///< share of scenes with a JPEG round trip
  SampleRange jpeg_quality{40.0, 95.0};
  /// Exposure time (motion blur), capped at 0.9 of the frame interval.
  SampleRange exposure_time_ms{0.0, 20.0};
};

/// The ranges random_scenario samples from.
inline constexpr RandomSceneRanges kRandomSceneRanges{};

/// What a random scene drew beyond the Scenario's fields (for reports and tests).
struct RandomSceneInfo {
  std::string platform;    ///< one of kRandomPlatforms (and the preset the scene names)
  std::string ego_motion;  ///< one of kRandomEgoMotions
  std::vector<std::string> shapes, paths;      ///< per obstacle, like Scenario::obstacles
  std::vector<double> start_ttc_over_horizon;  ///< per obstacle, the sampled start factor
};

/// The scene of `seed`: name "random-<seed>", a description listing the draws. `info`, when
/// given, receives the draws the Scenario does not hold.
Scenario random_scenario(std::uint32_t seed, RandomSceneInfo* info = nullptr);

/// Caps a scene for quick runs: an image larger than `max_size` is scaled down to fit (aspect
/// kept, focal length and principal point scaled with it), and frames are capped at
/// `max_frames` (0 = no cap). The truth stays consistent: it is rendered from the capped scene.
void cap_scenario(Scenario& s, cv::Size max_size, int max_frames);

}  // namespace sg::sim
