// Built-in scenarios (DESIGN 4). Unless noted they use the default camera (640x480, f 500 px,
// B 0.12 m, 30 fps, 1.2 m above the ground) and the default envelope (|X| <= 0.5 m,
// -1 <= Y <= 1 m, contact at Z = 0.5 m, horizon 3 s). The walker and car scenarios use their
// platform's envelope (core::platform_envelope) and camera. Boxes stand on the ground unless
// noted. Contact times in the comments follow box_collision(): t_c = (Z_near - z_contact) / (-V_z).
#include <cmath>
#include <functional>
#include <utility>

#include "sg/core/error.hpp"
#include "sg/core/platform.hpp"
#include "sg/sim/scenario.hpp"

namespace sg::sim {
namespace {

Scenario make(const char* name, const char* description, int frames) {
  Scenario s;
  s.name = name;
  s.description = description;
  s.frames = frames;
  return s;
}

/// A box of size (w, h, d) standing on the ground of `s` with its centre at (x, z).
Box standing(const Scenario& s, int id, cv::Vec3d size, double x, double z, cv::Vec3d velocity,
             std::uint32_t seed) {
  Box b;
  b.id = id;
  b.size_m = size;
  b.position_m = {x, s.height_m - size[1] / 2.0, z};
  b.velocity_mps = velocity;
  b.texture_seed = seed;
  return b;
}

Scenario head_on() {
  // Z_near 14.75 m at 3 m/s: contact at 4.75 s (frame 142.5); GT alarm from frame 53 (TTC 3 s).
  Scenario s = make("head-on", "a 1.0 x 1.5 x 0.5 m box approaches from 15 m at 3 m/s; collides",
                    143);
  s.obstacles.push_back(standing(s, 1, {1.0, 1.5, 0.5}, 0.0, 15.0, {0, 0, -3.0}, 101));
  return s;
}

Scenario head_on_fast() {
  // Z_near 24.75 m at 6 m/s: contact at 4.04 s (frame 121.25).
  Scenario s = make("head-on-fast",
                    "a 1.0 x 1.5 x 0.5 m box approaches from 25 m at 6 m/s; collides", 121);
  s.obstacles.push_back(standing(s, 1, {1.0, 1.5, 0.5}, 0.1, 25.0, {0, 0, -6.0}, 111));
  return s;
}

Scenario cold_start() {
  // Z_near 8.0 m at 3 m/s from the first frame: contact at 2.5 s (frame 75), so every frame is a
  // GT alarm frame (TTC <= 3 s from the start). The alarm can come no earlier than the chain's
  // first frames measure the approach (issue 36).
  Scenario s = make("cold-start",
                    "a 1.0 x 1.5 x 0.5 m box is already 8 m away approaching at 3 m/s when the "
                    "run starts; collides",
                    76);
  s.obstacles.push_back(standing(s, 1, {1.0, 1.5, 0.5}, 0.0, 8.25, {0, 0, -3.0}, 131));
  return s;
}

Scenario crossing() {
  // V_z = 0: never enters the envelope although it passes right in front of it.
  Scenario s = make("crossing",
                    "a 0.8 x 1.6 x 0.5 m box crosses from left to right 6 m ahead at 2 m/s; "
                    "never collides",
                    150);
  s.obstacles.push_back(standing(s, 1, {0.8, 1.6, 0.5}, -4.0, 6.0, {2.0, 0, 0}, 201));
  return s;
}

Scenario receding() {
  Scenario s = make("receding", "a 1.0 x 1.5 x 0.5 m box moves away from 4 m at 2 m/s", 150);
  s.obstacles.push_back(standing(s, 1, {1.0, 1.5, 0.5}, 0.0, 4.0, {0, 0, 2.0}, 301));
  return s;
}

Scenario static_scene() {
  Scenario s = make("static", "four boxes standing still at 3, 6, 10 and 16 m; nothing moves",
                    150);
  s.obstacles.push_back(standing(s, 1, {0.8, 1.2, 0.6}, -1.0, 3.0, {0, 0, 0}, 401));
  s.obstacles.push_back(standing(s, 2, {1.0, 1.8, 0.5}, 0.4, 6.0, {0, 0, 0}, 402));
  s.obstacles.push_back(standing(s, 3, {1.5, 2.5, 1.0}, 2.2, 10.0, {0, 0, 0}, 403));
  s.obstacles.push_back(standing(s, 4, {3.0, 4.0, 1.0}, -3.5, 16.0, {0, 0, 0}, 404));
  return s;
}

Scenario ego_wall() {
  // Z_near 14 m at 2 m/s: 0.8 m left at the last frame (t = 6.6 s); GT alarm from t = 3.75 s.
  Scenario s = make("ego-wall",
                    "the camera drives at 2 m/s towards a 6 x 3 m wall 14 m ahead and stops "
                    "0.8 m before it; collides",
                    199);
  s.ego_velocity_mps = {0, 0, 2.0};
  s.obstacles.push_back(standing(s, 1, {6.0, 3.0, 0.5}, 0.0, 14.25, {0, 0, 0}, 501));
  return s;
}

Scenario ego_pass() {
  // X extent [1.0, 1.6] m never overlaps |X| <= 0.5 m; the camera passes it at t = 4.5 s.
  Scenario s = make("ego-pass",
                    "the camera drives at 2 m/s past a 0.6 x 1.5 x 0.6 m box standing 1.3 m to "
                    "the right, 9 m ahead; never collides",
                    150);
  s.ego_velocity_mps = {0, 0, 2.0};
  s.obstacles.push_back(standing(s, 1, {0.6, 1.5, 0.6}, 1.3, 9.0, {0, 0, 0}, 601));
  return s;
}

Scenario two_obstacles() {
  // Box 1 (left): Z_near 9.75 m at 2 m/s, contact at 4.625 s with X extent [-0.72, -0.12]:
  // collides. Box 2 (right): X extent [1.7, 2.3] m, approaches at 1.5 m/s: never collides.
  Scenario s = make("two-obstacles",
                    "box 1 approaches diagonally from the left and collides; box 2 approaches on "
                    "the right and passes beside the envelope",
                    138);
  s.obstacles.push_back(standing(s, 1, {0.6, 1.5, 0.5}, -2.5, 10.0, {0.45, 0, -2.0}, 701));
  s.obstacles.push_back(standing(s, 2, {0.6, 1.5, 0.5}, 2.0, 8.0, {0, 0, -1.5}, 702));
  return s;
}

Scenario pedestrian() {
  // Z_near 7.85 m at 1.5 m/s: contact at 4.9 s with X extent [-0.055, 0.445]: collides.
  Scenario s = make("pedestrian",
                    "a thin 0.5 x 1.7 x 0.3 m box walks diagonally from the left into the path; "
                    "collides",
                    147);
  s.obstacles.push_back(standing(s, 1, {0.5, 1.7, 0.3}, -2.5, 8.0, {0.55, 0, -1.5}, 801));
  return s;
}

/// A scenario for a platform: its envelope for the ground truth, and its name.
Scenario for_platform(Scenario s, const char* platform) {
  s.platform = platform;
  s.envelope = core::platform_envelope(platform);
  return s;
}

Scenario walker(const char* name, const char* description, int frames) {
  Scenario s = for_platform(make(name, description, frames), "walker");
  s.height_m = 1.3;  // a travel aid worn on the chest
  s.ego_velocity_mps = {0, 0, 1.4};
  return s;
}

Scenario thin_pole() {
  // Z_near 7.97 m at 1.4 m/s: contact (0.4 m) at 5.41 s (frame 162); GT alarm from t = 2.41 s
  // (frame 73), when the pole is 4.6 m away and 6.5 px wide.
  Scenario s = walker("thin-pole",
                      "a walker at 1.4 m/s towards a 6 cm pole 3 m tall standing 8 m ahead, 15 cm "
                      "right of centre; collides",
                      160);
  s.obstacles.push_back(standing(s, 1, {0.06, 3.0, 0.06}, 0.15, 8.0, {0, 0, 0}, 901));
  return s;
}

Scenario overhang() {
  // A 1.2 x 0.2 x 0.2 m bar 1.6-1.8 m above the ground (Y -0.5..-0.3 for the camera at 1.3 m),
  // nothing below it. Z_near 7.9 m at 1.4 m/s: contact at 5.36 s; GT alarm from t = 2.36 s.
  Scenario s = walker("overhang",
                      "a walker at 1.4 m/s towards a bar at head height (1.6-1.8 m above the "
                      "ground, nothing below) 8 m ahead; collides",
                      158);
  Box bar;
  bar.id = 1;
  bar.size_m = {1.2, 0.2, 0.2};
  bar.position_m = {0.1, s.height_m - 1.7, 8.0};
  bar.texture_seed = 1001;
  s.obstacles.push_back(bar);
  return s;
}

Scenario turning() {
  // The camera turns in place (yaw +30 deg/s, to the right) through 150 degrees among boxes
  // parked 2.5-6 m away all around it: every static point sweeps sideways; nothing collides.
  Scenario s = make("turning",
                    "a robot turns in place at 30 deg/s among six parked boxes 2.5-6 m away; "
                    "never collides",
                    150);
  s.camera_motion.yaw_rate_dps = 30.0;
  const double kDeg = CV_PI / 180.0;
  const struct {
    double range_m, bearing_deg;
    cv::Vec3d size;
  } kParked[] = {{3.0, 10, {0.8, 1.2, 0.6}},  {5.0, 40, {1.0, 1.6, 0.8}},
                 {2.5, 70, {0.6, 1.0, 0.6}},  {4.0, 100, {1.2, 1.8, 0.6}},
                 {6.0, 130, {1.5, 2.0, 1.0}}, {3.5, 160, {0.8, 1.4, 0.8}}};
  int id = 1;
  for (const auto& p : kParked) {
    const double a = p.bearing_deg * kDeg;
    s.obstacles.push_back(standing(s, id, p.size, p.range_m * std::sin(a),
                                   p.range_m * std::cos(a), {0, 0, 0},
                                   static_cast<std::uint32_t>(1100 + id)));
    ++id;
  }
  return s;
}

Scenario car(const char* name, const char* description, int frames) {
  Scenario s = for_platform(make(name, description, frames), "car");
  s.camera.width = 960;
  s.camera.height = 400;
  s.camera.focal_px = 600.0;
  s.camera.baseline_m = 0.30;
  s.camera.cx = 479.5;
  s.camera.cy = 199.5;
  s.height_m = 1.3;
  s.ego_velocity_mps = {0, 0, 10.0};
  s.background_z_m = 150.0;
  s.background_height_m = 30.0;
  return s;
}

Scenario car_stopped() {
  // Rear 40 m ahead, camera at 10 m/s: contact (2 m) at 3.8 s (frame 114); GT alarm from t = 0.8 s
  // (frame 24), 30 m away, where the car's disparity is 6 px and grows 0.2 px a frame.
  Scenario s = car("car-stopped",
                   "a car camera (f 600 px, B 0.30 m) at 10 m/s towards a car stopped 40 m ahead "
                   "in its lane, beside a car parked in the next lane; collides",
                   112);
  s.obstacles.push_back(standing(s, 1, {1.8, 1.5, 4.5}, 0.0, 42.25, {0, 0, 0}, 1201));
  s.obstacles.push_back(standing(s, 2, {1.8, 1.5, 4.5}, -3.5, 30.0, {0, 0, 0}, 1202));
  return s;
}

Scenario car_cut_in() {
  // The other car drives at 6 m/s (the camera at 10 m/s), rear 24 m ahead in the next lane
  // (X = 3.5 m); it pulls in over 2 s (lateral -3.2 m/s^2 for 1 s, then +3.2 m/s^2 for 1 s:
  // X 3.5 -> 0.3 m), 16 m ahead; the GT alarm starts at t = 2.5 s (14 m, TTC 3 s); at t = 3 s it
  // brakes at 4 m/s^2 to a stop: contact (2 m) at t = 4.45 s.
  Scenario s = car("car-cut-in",
                   "a car camera at 10 m/s; a car at 6 m/s pulls in from the next lane 16 m "
                   "ahead and brakes hard; collides",
                   132);
  Box other = standing(s, 1, {1.8, 1.5, 4.5}, 3.5, 24.0 + 2.25, {0, 0, 6.0}, 1301);
  other.accelerations = {{0.0, {-3.2, 0, 0}},
                         {1.0, {3.2, 0, 0}},
                         {2.0, {0, 0, 0}},
                         {3.0, {0, 0, -4.0}},
                         {4.5, {0, 0, 0}}};
  s.obstacles.push_back(other);
  return s;
}

const std::vector<std::pair<std::string, std::function<Scenario()>>>& registry() {
  static const std::vector<std::pair<std::string, std::function<Scenario()>>> kAll = {
      {"head-on", head_on},         {"crossing", crossing},
      {"receding", receding},       {"static", static_scene},
      {"ego-wall", ego_wall},       {"ego-pass", ego_pass},
      {"two-obstacles", two_obstacles}, {"head-on-fast", head_on_fast},
      {"pedestrian", pedestrian},   {"thin-pole", thin_pole},
      {"overhang", overhang},       {"turning", turning},
      {"car-stopped", car_stopped}, {"car-cut-in", car_cut_in},
      {"cold-start", cold_start},
  };
  return kAll;
}

}  // namespace

std::vector<std::string> builtin_scenario_names() {
  std::vector<std::string> names;
  for (const auto& entry : registry()) names.push_back(entry.first);
  return names;
}

Scenario builtin_scenario(const std::string& name) {
  for (const auto& entry : registry())
    if (entry.first == name) return entry.second();
  std::string list;
  for (const auto& n : builtin_scenario_names()) list += (list.empty() ? "" : ", ") + n;
  throw core::InputError("unknown scenario '" + name + "' (built-in: " + list + ")");
}

}  // namespace sg::sim
