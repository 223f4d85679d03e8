#include "sg/sim/random_scene.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include "sg/core/platform.hpp"
#include "sg/sim/renderer.hpp"

namespace sg::sim {
namespace {

constexpr double kDeg = CV_PI / 180.0;
constexpr int kWalker = 0, kRobot = 1, kCar = 2, kDrone = 3;

/// Every draw of a scene, from one generator in a fixed order.
class Draw {
 public:
  explicit Draw(std::uint32_t seed) : rng_(seed) {}
  /// Uniform in [r.lo, r.hi].
  double in(const SampleRange& r) {
    if (r.hi <= r.lo) return r.lo;
    return std::min(r.hi, std::uniform_real_distribution<double>(r.lo, r.hi)(rng_));
  }
  /// Uniform in 0..n-1.
  int index(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng_); }
  bool chance(double p) { return in({0.0, 1.0}) < p; }
  /// -1 or +1.
  double sign() { return index(2) == 0 ? -1.0 : 1.0; }
  std::uint32_t seed() { return static_cast<std::uint32_t>(rng_()); }
  /// A texture kind drawn with kRandomSceneRanges.texture_weights.
  TextureKind texture() {
    const auto& w = kRandomSceneRanges.texture_weights;
    double u = in({0.0, 1.0});
    for (std::size_t k = 0; k + 1 < w.size(); ++k) {
      if (u < w[k]) return static_cast<TextureKind>(k);
      u -= w[k];
    }
    return static_cast<TextureKind>(w.size() - 1);
  }

 private:
  std::mt19937 rng_;
};

void sample_camera(Draw& d, Scenario& s, double& duration_s) {
  const RandomSceneRanges& r = kRandomSceneRanges;
  const auto& size = kRandomImageSizes[static_cast<std::size_t>(
      d.index(static_cast<int>(kRandomImageSizes.size())))];
  s.camera.width = size[0];
  s.camera.height = size[1];
  const double fov = d.in(r.fov_deg);
  s.camera.focal_px = 0.5 * s.camera.width / std::tan(0.5 * fov * kDeg);
  s.camera.cx = 0.5 * (s.camera.width - 1);
  s.camera.cy = 0.5 * (s.camera.height - 1);
  s.camera.baseline_m = d.in(r.baseline_m);
  s.camera.fps = d.in(r.fps);
  duration_s = d.in(r.duration_s);
  s.frames = std::max(2, static_cast<int>(std::lround(duration_s * s.camera.fps)));
  // Pixel areas were written for 640x480.
  s.min_area_px = std::max(1, static_cast<int>(std::lround(s.min_area_px * s.camera.width *
                                                           s.camera.height / (640.0 * 480.0))));
}

void sample_motion(Draw& d, int platform, double duration_s, Scenario& s,
                   RandomSceneInfo& info) {
  const RandomSceneRanges& r = kRandomSceneRanges;
  const auto p = static_cast<std::size_t>(platform);
  s.height_m = d.in(r.height_m[p]);
  const int motion = d.index(static_cast<int>(kRandomEgoMotions.size()));
  info.ego_motion = kRandomEgoMotions[static_cast<std::size_t>(motion)];
  double speed = d.in(r.ego_speed_mps[p]);
  if (info.ego_motion == "turning") {
    s.camera_motion.yaw_rate_dps = d.sign() * d.in(r.yaw_rate_dps);
    const double share = d.in({0.0, 1.0});
    if (platform == kCar) {
      // No tighter than a car's turning circle, no harder sideways than a driver turns.
      const double yaw_rps = std::abs(s.camera_motion.yaw_rate_dps) * kDeg;
      const double lo = yaw_rps * r.car_min_turn_radius_m;
      const double hi = std::min(speed, r.car_max_lateral_mps2 / yaw_rps);
      speed = lo + share * (hi - lo);
    } else {
      speed *= share;
    }
    s.ego_follows_heading = true;  // a platform drives where it heads: an arc
  } else if (info.ego_motion == "still") {
    speed = 0.0;
  }
  s.ego_velocity_mps = cv::Vec3d(0, 0, speed);
  if (info.ego_motion == "accelerating") {
    const double start = speed * d.in(r.start_speed_share), ramp = d.in(r.speed_ramp_s);
    s.ego_velocity_mps = cv::Vec3d(0, 0, start);
    s.ego_accelerations = {{0.0, cv::Vec3d(0, 0, (speed - start) / ramp)},
                           {ramp, cv::Vec3d(0, 0, 0)}};
  } else if (info.ego_motion == "stopping") {
    const double from = d.in(r.brake_start_share) * duration_s, ramp = d.in(r.brake_ramp_s);
    s.ego_accelerations = {{from, cv::Vec3d(0, 0, -speed / ramp)},
                           {from + ramp, cv::Vec3d(0, 0, 0)}};
  }
  s.camera_motion.pitch_deg = d.in(r.pitch_deg);
  s.camera_motion.roll_deg = d.in(r.roll_deg);
  const double sway = (platform == kWalker || platform == kDrone) ? 1.0 : 1.0 / 3.0;
  s.camera_motion.pitch_amplitude_deg = sway * d.in(r.pitch_amplitude_deg);
  s.camera_motion.roll_amplitude_deg = sway * d.in(r.roll_amplitude_deg);
  s.camera_motion.oscillation_hz = d.in(r.sway_hz);
}

/// One obstacle: shape, path and start, in the world frame (the camera frame at t = 0).
Box sample_obstacle(Draw& d, int platform, const Scenario& s, double duration_s, int id,
                    RandomSceneInfo& info) {
  const RandomSceneRanges& r = kRandomSceneRanges;
  const core::Envelope& e = s.envelope;
  const int shape = d.index(static_cast<int>(kRandomShapes.size()));
  const int path = d.index(static_cast<int>(kRandomPaths.size()));
  const std::string path_name = kRandomPaths[static_cast<std::size_t>(path)];
  Box b;
  b.id = id;
  for (int a = 0; a < 3; ++a)
    b.size_m[a] =
        d.in(r.shape_size_m[static_cast<std::size_t>(shape)][static_cast<std::size_t>(a)]);
  b.texture_seed = d.seed();
  b.texture = d.texture();
  const double w = b.size_m[0], h = b.size_m[1], depth = b.size_m[2];
  double y = s.height_m - 0.5 * h;  // standing on the ground
  if (std::string(kRandomShapes[static_cast<std::size_t>(shape)]) == "bar")
    y = s.height_m - d.in(r.bar_clearance_m) - 0.5 * h;
  if (platform == kDrone) y = d.in(r.drone_obstacle_y_m);

  const bool inside = d.chance(0.5);
  const double k = d.in(inside ? r.start_inside_horizon : r.start_outside_horizon);
  const double ttc = k * e.horizon_s;  // time to contact at frame 0 on its path
  const double ego = s.ego_velocity_mps[2];
  const double speed =
      path_name == "stopped" ? 0.0 : d.in(r.obstacle_speed_mps[static_cast<std::size_t>(platform)]);
  const double side = d.sign();
  const double centre_x = d.in({-0.5 * e.half_width_m, 0.5 * e.half_width_m});
  double x0 = centre_x, z_near = 0.0;
  cv::Vec3d v(0, 0, 0);
  if (path_name == "head-on" || path_name == "stopped" || path_name == "near-miss") {
    v = cv::Vec3d(0, 0, -speed);
    if (path_name == "near-miss") x0 = side * (e.half_width_m + 0.5 * w + d.in(r.near_miss_gap_m));
    z_near = e.z_contact_m + std::max(ego + speed, 0.5) * ttc;
  } else if (path_name == "oblique") {
    const double angle = d.in(r.oblique_angle_deg) * kDeg;
    v = cv::Vec3d(-side * speed * std::sin(angle), 0, -speed * std::cos(angle));
    x0 = centre_x + side * speed * std::sin(angle) * ttc;
    z_near = e.z_contact_m + std::max(ego + speed * std::cos(angle), 0.5) * ttc;
  } else if (path_name == "crossing") {
    const double cross_s = std::min(ttc, 0.8 * duration_s);  // when it crosses X = 0
    v = cv::Vec3d(side * speed, 0, 0);
    x0 = -side * speed * cross_s;
    z_near = e.z_contact_m + ego * cross_s + d.in(r.crossing_gap_m);
  } else {  // receding
    v = cv::Vec3d(0, 0, ego + speed);
    z_near = e.z_contact_m + std::max(ego, 1.0) * ttc;
  }
  b.position_m = cv::Vec3d(x0, y, z_near + 0.5 * depth);
  b.velocity_mps = v;
  info.shapes.push_back(kRandomShapes[static_cast<std::size_t>(shape)]);
  info.paths.push_back(path_name);
  info.start_ttc_over_horizon.push_back(k);
  return b;
}

void sample_sensor(Draw& d, double duration_s, Scenario& s) {
  const RandomSceneRanges& r = kRandomSceneRanges;
  s.noise_sigma = d.in(r.noise_sigma);
  s.right_gain = d.in(r.right_gain);
  s.noise_seed = d.seed();
  s.effects.right_shift_y_px = d.in(r.right_shift_y_px);
  s.effects.exposure_time_s = std::min(d.in(r.exposure_time_ms) * 1e-3, 0.9 / s.camera.fps);
  s.effects.vignetting = d.in(r.vignetting);
  const int steps = d.index(r.max_exposure_steps + 1);
  std::vector<double> times;
  for (int i = 0; i < steps; ++i) times.push_back(d.in({0.05 * duration_s, 0.95 * duration_s}));
  std::sort(times.begin(), times.end());
  for (double t : times) {
    if (!s.effects.exposure_steps.empty() && t <= s.effects.exposure_steps.back().from_s) continue;
    s.effects.exposure_steps.push_back({t, d.in(r.exposure_gain)});
  }
  if (d.chance(r.jpeg_probability))
    s.effects.jpeg_quality = static_cast<int>(std::lround(d.in(r.jpeg_quality)));
}

/// Casters placed so that their shadows start on the ground in view and drift.
void sample_shadows(Draw& d, Scenario& s) {
  const RandomSceneRanges& r = kRandomSceneRanges;
  if (!d.chance(r.shadow_probability)) return;
  const double elevation = d.in(r.sun_elevation_deg) * kDeg, azimuth = d.in({0.0, 360.0}) * kDeg;
  s.shadows.to_light = cv::Vec3d(std::cos(elevation) * std::sin(azimuth), -std::sin(elevation),
                                 std::cos(elevation) * std::cos(azimuth));
  const int count = 1 + d.index(r.max_shadow_casters);
  for (int i = 0; i < count; ++i) {
    ShadowCaster c;
    const cv::Vec3d ground(d.in(r.shadow_side_m), s.height_m, d.in(r.shadow_ahead_m));
    const double up = d.in(r.caster_height_m);
    c.position_m = ground + s.shadows.to_light * (up / std::sin(elevation));
    const double speed = d.in(r.caster_speed_mps), heading = d.in({0.0, 360.0}) * kDeg;
    c.velocity_mps = cv::Vec3d(speed * std::sin(heading), 0, speed * std::cos(heading));
    c.radius_m = d.in(r.caster_radius_m);
    c.darkness = d.in(r.shadow_darkness);
    s.shadows.casters.push_back(c);
  }
}

/// Whether boxes a and b overlap at some frame time of the first `duration_s` seconds (frames at
/// `fps`): solid obstacles do not pass through each other, and one that would is left out.
bool overlap_in_scene(const Box& a, const Box& b, double duration_s, double fps) {
  const int frames = static_cast<int>(std::ceil(duration_s * fps));
  for (int i = 0; i <= frames; ++i) {
    const double t = i / fps;
    const cv::Vec3d gap = box_position(a, t) - box_position(b, t);
    bool apart = false;
    for (int k = 0; k < 3; ++k) apart |= std::abs(gap[k]) >= 0.5 * (a.size_m[k] + b.size_m[k]);
    if (!apart) return true;
  }
  return false;
}

std::string describe(const Scenario& s, const RandomSceneInfo& info) {
  std::ostringstream out;
  out << info.platform << ", " << s.camera.width << "x" << s.camera.height << ", "
      << info.ego_motion << " at " << std::round(s.ego_velocity_mps[2] * 10) / 10 << " m/s";
  if (info.shapes.empty()) out << ", no obstacle";
  for (std::size_t i = 0; i < info.shapes.size(); ++i)
    out << (i == 0 ? "; " : ", ") << info.shapes[i] << " " << info.paths[i]
        << (info.start_ttc_over_horizon[i] < 1.0 ? " (inside the horizon)"
                                                 : " (outside the horizon)");
  return out.str();
}

}  // namespace

Scenario random_scenario(std::uint32_t seed, RandomSceneInfo* info_out) {
  const RandomSceneRanges& r = kRandomSceneRanges;
  Draw d(seed);
  RandomSceneInfo info;
  Scenario s;
  s.name = "random-" + std::to_string(seed);
  const int platform = d.index(static_cast<int>(kRandomPlatforms.size()));
  info.platform = kRandomPlatforms[static_cast<std::size_t>(platform)];
  s.platform = info.platform;
  s.envelope = core::platform_envelope(s.platform);
  double duration_s = 0.0;
  sample_camera(d, s, duration_s);
  sample_motion(d, platform, duration_s, s, info);
  s.ground_seed = d.seed();
  s.background_seed = d.seed();
  const int count = d.index(r.max_obstacles + 1);
  double far_z = 0.0;
  for (int i = 0; i < count; ++i) {
    const int id = static_cast<int>(s.obstacles.size()) + 1;
    RandomSceneInfo drawn = info;
    Box b = sample_obstacle(d, platform, s, duration_s, id, drawn);
    // The draws are made either way, so that leaving an obstacle out changes nothing else.
    if (std::any_of(s.obstacles.begin(), s.obstacles.end(), [&](const Box& other) {
          return overlap_in_scene(b, other, duration_s, s.camera.fps);
        }))
      continue;
    info = std::move(drawn);
    s.obstacles.push_back(b);
    far_z = std::max(
        far_z, b.position_m[2] + 0.5 * b.size_m[2] + std::max(0.0, b.velocity_mps[2]) * duration_s);
  }
  // The background wall stays beyond every obstacle and ahead of the camera all scene long.
  s.background_z_m =
      std::max({d.in(r.background_z_m), far_z + 5.0, s.ego_velocity_mps[2] * duration_s + 10.0});
  sample_sensor(d, duration_s, s);
  s.ground_texture = d.texture();
  s.background_texture = d.texture();
  sample_shadows(d, s);
  // A camera that has hit something has nothing left to warn of, and the frames after would put
  // it inside the obstacle: the scene ends at its first contact.
  s.frames = frames_to_first_contact(s);
  s.description = describe(s, info);
  if (info_out) *info_out = info;
  return s;
}

void cap_scenario(Scenario& s, cv::Size max_size, int max_frames) {
  if (max_frames > 0) s.frames = std::min(s.frames, std::max(2, max_frames));
  if (max_size.width <= 0 || max_size.height <= 0) return;
  const double scale = std::min({1.0, static_cast<double>(max_size.width) / s.camera.width,
                                 static_cast<double>(max_size.height) / s.camera.height});
  if (scale >= 1.0) return;
  const int width = std::max(16, static_cast<int>(std::lround(s.camera.width * scale)));
  const int height = std::max(16, static_cast<int>(std::lround(s.camera.height * scale)));
  const double sx = static_cast<double>(width) / s.camera.width;
  const double area = static_cast<double>(width) * height / (s.camera.width * s.camera.height);
  s.camera.focal_px *= sx;
  s.camera.cx = (s.camera.cx + 0.5) * sx - 0.5;
  s.camera.cy = (s.camera.cy + 0.5) * (static_cast<double>(height) / s.camera.height) - 0.5;
  s.camera.width = width;
  s.camera.height = height;
  s.min_area_px = std::max(1, static_cast<int>(std::lround(s.min_area_px * area)));
}

}  // namespace sg::sim
