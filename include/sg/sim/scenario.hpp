#pragma once
/// Scenarios for the simulator (DESIGN 4): a camera, a textured ground and background, and boxes.
/// World frame = the camera frame at t = 0 (x right, y down, z forward, metres); the camera moves
/// with ego_velocity and may turn (CameraMotion); the ground is the plane Y = height_m.
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sg/core/camera.hpp"
#include "sg/core/params.hpp"

namespace sg::sim {

/// From time from_s on (until the next phase), the box accelerates at acceleration_mps2.
struct AccelerationPhase {
  double from_s = 0.0;                   ///< start of the phase, s (phases in increasing order)
  cv::Vec3d acceleration_mps2{0, 0, 0};  ///< world frame, m/s^2
};

/// Surface texture kinds (docs/random-suite.md): value noise at every scale ("noise", the
/// default), the same at an eighth of its contrast ("low"), a checkerboard of tiles ("tiles"),
/// parallel stripes at an angle ("stripes"), and rows of glyph-like marks ("clutter"). The
/// periodic kinds keep a weak noise on top, as real tiles and paint do.
enum class TextureKind : std::uint8_t { kNoise, kLow, kTiles, kStripes, kClutter };
/// Names of the texture kinds, indexed by the enum: "noise", "low", "tiles", "stripes", "clutter".
const std::vector<std::string>& texture_kind_names();
/// The kind of `name`; throws core::InputError listing the names for an unknown one.
TextureKind texture_kind(const std::string& name);

/// An axis-aligned box (world frame). A pole is a narrow box from the ground up; an overhang is a
/// box whose bottom is above the ground (nothing below it).
struct Box {
  int id = 1;                          ///< >= 1, unique; written to the ids map
  cv::Vec3d size_m{1.0, 1.5, 0.5};     ///< width (X), height (Y), depth (Z), m
  cv::Vec3d position_m{0, 0, 15};      ///< centre at t = 0, world frame, m
  cv::Vec3d velocity_mps{0, 0, 0};     ///< velocity at t = 0, world frame, m/s
  /// Piecewise-constant acceleration (empty: constant velocity); before the first phase, none.
  std::vector<AccelerationPhase> accelerations;
  std::uint32_t texture_seed = 1;      ///< texture fixed to the box
  TextureKind texture = TextureKind::kNoise;
};

/// Centre of the box at time t_s, world frame, m (integrates the acceleration phases exactly).
cv::Vec3d box_position(const Box& box, double t_s);
/// Velocity of the box at time t_s, world frame, m/s.
cv::Vec3d box_velocity(const Box& box, double t_s);

/// The camera's own rotation (the left camera turns about its optical centre). Camera-to-world
/// rotation at time t: R(t) = R_y(yaw) R_x(pitch) R_z(roll), with yaw = yaw_rate * t (positive
/// turns right: the optical axis swings towards +X), pitch = pitch_deg + pitch_amplitude
/// sin(2 pi f t) (positive looks up), roll = roll_deg + roll_amplitude sin(2 pi f t + pi/2),
/// f = oscillation_hz: a mounting tilt plus the sway of a walking or flying platform. All zero
/// (the default): the camera keeps the world axes.
struct CameraMotion {
  double yaw_rate_dps = 0.0;         ///< deg/s
  double pitch_amplitude_deg = 0.0;  ///< deg
  double roll_amplitude_deg = 0.0;   ///< deg
  double oscillation_hz = 1.0;       ///< Hz, > 0
  double pitch_deg = 0.0;            ///< fixed pitch of the mounting, deg, -45..45
  double roll_deg = 0.0;             ///< fixed roll of the mounting, deg, -45..45
  /// True when any rotation is set.
  bool rotates() const {
    return yaw_rate_dps != 0.0 || pitch_deg != 0.0 || roll_deg != 0.0 ||
           pitch_amplitude_deg != 0.0 || roll_amplitude_deg != 0.0;
  }
};

/// A shadow caster out of view (a tree, a cloud, a passer-by): a sphere whose shadow, cast along
/// Shadows::to_light, darkens the ground, the background and the boxes it falls on.
struct ShadowCaster {
  cv::Vec3d position_m{0, -5, 10};  ///< centre at t = 0, world frame, m
  cv::Vec3d velocity_mps{0, 0, 0};  ///< world frame, m/s
  double radius_m = 1.0;            ///< > 0; the penumbra spans 0.85..1.15 of it
  double darkness = 0.5;            ///< share of the light it blocks in its umbra, 0..0.95
};

/// Moving cast shadows: a surface point P is shaded by (1 - darkness) where the ray P + s L
/// (s > 0, L = to_light normalised) passes within the umbra of a caster. The truth maps ignore
/// them (a shadow is not an obstacle).
struct Shadows {
  cv::Vec3d to_light{0.3, -1.0, -0.4};  ///< direction towards the light, world frame (y down)
  std::vector<ShadowCaster> casters;    ///< none: no shadow
};

/// From time from_s on (until the next step), every pixel of both images is multiplied by gain:
/// an auto-exposure step. Applied after shading and noise; the ground truth does not change.
struct ExposureStep {
  double from_s = 0.0;  ///< start, s (steps in increasing order)
  double gain = 1.0;    ///< > 0
};

/// Image effects of a real camera, applied to the rendered images in this order: exposure gain,
/// vignetting, the right image's vertical shift, a JPEG round trip. The ground-truth maps stay
/// those of the ideal pair. All defaults: none (the images are the ray caster's).
struct ImageEffects {
  std::vector<ExposureStep> exposure_steps;  ///< before the first step: gain 1
  /// Brightness falls by this fraction at the image corners: gain 1 - v (r / r_corner)^2 with r
  /// the distance to the image centre, 0..0.9; the same on both images.
  double vignetting = 0.0;
  /// The right image moves down by this many pixels (bilinear; a rectification error), -2..2.
  double right_shift_y_px = 0.0;
  /// JPEG quality of a compress-decompress round trip of each image, 1..100; 0 = none.
  int jpeg_quality = 0;
  /// Exposure time, s, 0..0.1 (0 = an instant): each image is the mean of the scene over
  /// [t - e/2, t + e/2], approximated by sampling it along each pixel's own image motion (the
  /// ground-truth flow of that camera scaled to the exposure); applied before noise and the
  /// effects above.
  double exposure_time_s = 0.0;
  /// True when any effect applied after rendering is set (exposure_time_s is part of rendering).
  bool any() const {
    return !exposure_steps.empty() || vignetting != 0.0 || right_shift_y_px != 0.0 ||
           jpeg_quality != 0;
  }
};

/// Camera-to-world rotation of the camera at time t_s (see CameraMotion).
cv::Matx33d camera_rotation(const CameraMotion& m, double t_s);

struct Scenario;
/// The camera's velocity at time t_s in the frame ego_velocity_mps is given in (world, or the
/// heading's with ego_follows_heading): ego_velocity_mps plus the integral of ego_accelerations.
cv::Vec3d ego_heading_velocity(const Scenario& s, double t_s);
/// The camera's velocity at time t_s, world frame, m/s.
cv::Vec3d ego_velocity(const Scenario& s, double t_s);
/// The camera's position at time t_s, world frame, m (the origin at t = 0): the integral of
/// ego_velocity (closed form, also through a turn).
cv::Vec3d ego_position(const Scenario& s, double t_s);
/// Where the camera would be at time t_s + tau_s had it kept from t_s on the velocity it has then
/// (in the heading's frame, still turning at the yaw rate): the path a time to contact
/// extrapolates. Without ego_accelerations, ego_position(s, t_s + tau_s).
cv::Vec3d ego_coasting_position(const Scenario& s, double t_s, double tau_s);

struct Scenario {
  std::string name;
  std::string description;
  core::Camera camera;                    ///< 640x480, f 500 px, B 0.12 m, 30 fps by default
  double height_m = 1.2;                  ///< camera height above the ground, m
  cv::Vec3d ego_velocity_mps{0, 0, 0};    ///< camera velocity, world frame, m/s
  CameraMotion camera_motion;             ///< the camera's own rotation (default: none)
  /// False: the camera moves at ego_velocity_mps in the world frame whatever its yaw (a robot
  /// turning in place, a camera panning). True: ego_velocity_mps is the velocity in the frame of
  /// the camera's heading, which turns at camera_motion.yaw_rate_dps, so that the camera drives
  /// along an arc of radius |v| / yaw rate, as a car does through a bend.
  bool ego_follows_heading = false;
  /// Piecewise-constant acceleration of the camera, in the frame of ego_velocity_mps (empty:
  /// constant speed); a platform that speeds up or brakes. Phases as for Box::accelerations.
  std::vector<AccelerationPhase> ego_accelerations;
  /// Platform preset the scenario is made for ("" = none, "robot", "walker", "car";
  /// core::platform_names()): `run` and `eval` apply its detector settings unless --platform or
  /// the config's `platform` key chooses another.
  std::string platform;
  int frames = 150;                       ///< frames to render
  double background_z_m = 40.0;           ///< textured wall facing the camera at this depth, m
  /// Height of that wall above the ground, m; rays passing above it see a uniform sky (disparity 0).
  double background_height_m = 15.0;
  std::uint32_t ground_seed = 11;         ///< ground texture
  std::uint32_t background_seed = 12;     ///< background texture
  TextureKind ground_texture = TextureKind::kNoise;
  TextureKind background_texture = TextureKind::kNoise;
  Shadows shadows;                        ///< moving cast shadows (default: none)
  double noise_sigma = 1.0;               ///< Gaussian pixel noise, gray levels (0 = none)
  double right_gain = 1.0;                ///< brightness gain of the right camera (photometric mismatch)
  std::uint32_t noise_seed = 7;           ///< noise is a fixed function of (seed, frame, side)
  /// A camera pixel integrates the light over its area: with edge_samples > 1 a pixel where a
  /// surface ends (its centre ray hits another surface or face than a 4-neighbour's) is shaded
  /// as the mean of edge_samples x edge_samples rays spread over the pixel, 1..8; 1 = one ray
  /// through the centre (point sampling). Point sampling snaps silhouettes to whole pixels, so
  /// a thin pole's matched disparity steps instead of growing smoothly as it nears, which no
  /// camera does (docs/inputs.md, Scenarios); hence 4 x 4 by default.
  int edge_samples = 4;
  ImageEffects effects;                   ///< exposure, vignetting, misalignment, compression
  std::vector<Box> obstacles;
  core::Envelope envelope;                ///< for the ground-truth collision test
  int min_area_px = 150;                  ///< GT alarm: a colliding obstacle covers at least this
};

/// Names of the built-in scenarios (head-on, crossing, receding, static, ego-wall, ego-pass,
/// two-obstacles, ...).
std::vector<std::string> builtin_scenario_names();
/// A built-in scenario; throws core::InputError naming the known ones for an unknown name.
Scenario builtin_scenario(const std::string& name);
/// A scenario from a YAML (or JSON) file; unspecified fields keep the defaults above. A file with
/// `random: {seed: S}` starts from random_scenario(S) (sg/sim/random_scene.hpp) instead, and its
/// other keys override that scene's fields (a given `obstacles` list replaces the sampled one).
/// Throws core::InputError naming the file and the bad field.
Scenario load_scenario_file(const std::string& path);
/// A built-in name, or else a path to a scenario file; throws core::InputError listing the
/// built-ins when it is neither.
Scenario resolve_scenario(const std::string& name_or_path);
/// The scenario as YAML text with every field, readable by load_scenario_file.
std::string to_yaml(const Scenario& s);
/// Writes to_yaml(s) to `path`; throws core::InputError when the file cannot be written.
void save_scenario_file(const Scenario& s, const std::string& path);
/// Every violation as text; empty when valid.
std::vector<std::string> validate(const Scenario& s);

}  // namespace sg::sim
