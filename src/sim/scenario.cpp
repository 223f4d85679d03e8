#include "sg/sim/scenario.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "sg/core/checker.hpp"
#include "sg/core/error.hpp"
#include "sg/core/platform.hpp"
#include "sg/core/yaml_text.hpp"
#include "sg/sim/random_scene.hpp"

namespace sg::sim {
namespace {

bool finite(const cv::Vec3d& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

std::string to_text(double v) {
  char buf[64];
  const auto result = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, result.ptr);
}

std::string to_text(const cv::Vec3d& v) {
  std::string out = "[";
  out += to_text(v[0]);
  out += ", ";
  out += to_text(v[1]);
  out += ", ";
  out += to_text(v[2]);
  out += "]";
  return out;
}

using core::Checker;

// ---- YAML reading -------------------------------------------------------------------------------

/// Reads typed fields and throws InputError naming the file, line and field on any problem.
class YamlReader {
 public:
  explicit YamlReader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const YAML::Node& node, const std::string& field,
                         const std::string& problem) const {
    std::string where = file_;
    if (node.IsDefined() && node.Mark().line >= 0)
      where += ":" + std::to_string(node.Mark().line + 1);
    throw core::InputError(where + ": field '" + field + "': " + problem);
  }

  void expect_map(const YAML::Node& node, const std::string& field,
                  const std::set<std::string>& known) const {
    if (!node.IsMap()) fail(node, field, "expected a mapping");
    for (const auto& kv : node) {
      std::string key;
      try {
        key = kv.first.as<std::string>();
      } catch (const YAML::Exception&) {
        fail(kv.first, field, "keys must be strings");
      }
      if (!known.count(key)) {
        std::string list;
        for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
        const std::string name = field.empty() ? key : field + "." + key;
        fail(kv.first, name, "unknown key (known: " + list + ")");
      }
    }
  }

  double number(const YAML::Node& node, const std::string& field) const {
    if (!node.IsScalar()) fail(node, field, "expected a number");
    try {
      return node.as<double>();
    } catch (const YAML::Exception&) {
      fail(node, field, "expected a number, got '" + node.Scalar() + "'");
    }
  }

  bool boolean(const YAML::Node& node, const std::string& field) const {
    if (!node.IsScalar()) fail(node, field, "expected true or false");
    try {
      return node.as<bool>();
    } catch (const YAML::Exception&) {
      fail(node, field, "expected true or false, got '" + node.Scalar() + "'");
    }
  }

  int integer(const YAML::Node& node, const std::string& field) const {
    if (!node.IsScalar()) fail(node, field, "expected an integer");
    try {
      return node.as<int>();
    } catch (const YAML::Exception&) {
      fail(node, field, "expected an integer, got '" + node.Scalar() + "'");
    }
  }

  std::uint32_t seed(const YAML::Node& node, const std::string& field) const {
    if (!node.IsScalar()) fail(node, field, "expected an integer in 0..4294967295");
    long long v = -1;
    try {
      v = node.as<long long>();
    } catch (const YAML::Exception&) {
      fail(node, field, "expected an integer in 0..4294967295, got '" + node.Scalar() + "'");
    }
    if (v < 0 || v > static_cast<long long>(std::numeric_limits<std::uint32_t>::max()))
      fail(node, field, "expected an integer in 0..4294967295, got " + std::to_string(v));
    return static_cast<std::uint32_t>(v);
  }

  std::string text(const YAML::Node& node, const std::string& field) const {
    if (!node.IsScalar()) fail(node, field, "expected a string");
    return node.Scalar();
  }

  cv::Vec3d vec3(const YAML::Node& node, const std::string& field) const {
    if (!node.IsSequence() || node.size() != 3) fail(node, field, "expected [x, y, z]");
    cv::Vec3d v;
    for (int i = 0; i < 3; ++i)
      v[i] = number(node[i], field + "[" + std::to_string(i) + "]");
    return v;
  }

 private:
  std::string file_;
};

void read_camera(const YamlReader& r, const YAML::Node& n, core::Camera& c) {
  r.expect_map(n, "camera", {"width", "height", "focal_px", "baseline_m", "cx", "cy", "fps"});
  if (n["width"]) c.width = r.integer(n["width"], "camera.width");
  if (n["height"]) c.height = r.integer(n["height"], "camera.height");
  if (n["focal_px"]) c.focal_px = r.number(n["focal_px"], "camera.focal_px");
  if (n["baseline_m"]) c.baseline_m = r.number(n["baseline_m"], "camera.baseline_m");
  if (n["cx"]) c.cx = r.number(n["cx"], "camera.cx");
  if (n["cy"]) c.cy = r.number(n["cy"], "camera.cy");
  if (n["fps"]) c.fps = r.number(n["fps"], "camera.fps");
}

void read_envelope(const YamlReader& r, const YAML::Node& n, core::Envelope& e) {
  r.expect_map(n, "envelope",
               {"half_width_m", "y_top_m", "y_bottom_m", "z_contact_m", "horizon_s"});
  if (n["half_width_m"]) e.half_width_m = r.number(n["half_width_m"], "envelope.half_width_m");
  if (n["y_top_m"]) e.y_top_m = r.number(n["y_top_m"], "envelope.y_top_m");
  if (n["y_bottom_m"]) e.y_bottom_m = r.number(n["y_bottom_m"], "envelope.y_bottom_m");
  if (n["z_contact_m"]) e.z_contact_m = r.number(n["z_contact_m"], "envelope.z_contact_m");
  if (n["horizon_s"]) e.horizon_s = r.number(n["horizon_s"], "envelope.horizon_s");
}

void read_camera_motion(const YamlReader& r, const YAML::Node& n, CameraMotion& m) {
  r.expect_map(n, "camera_motion",
               {"yaw_rate_dps", "pitch_deg", "roll_deg", "pitch_amplitude_deg",
                "roll_amplitude_deg", "oscillation_hz"});
  if (n["yaw_rate_dps"]) m.yaw_rate_dps = r.number(n["yaw_rate_dps"], "camera_motion.yaw_rate_dps");
  if (n["pitch_deg"]) m.pitch_deg = r.number(n["pitch_deg"], "camera_motion.pitch_deg");
  if (n["roll_deg"]) m.roll_deg = r.number(n["roll_deg"], "camera_motion.roll_deg");
  if (n["pitch_amplitude_deg"])
    m.pitch_amplitude_deg = r.number(n["pitch_amplitude_deg"], "camera_motion.pitch_amplitude_deg");
  if (n["roll_amplitude_deg"])
    m.roll_amplitude_deg = r.number(n["roll_amplitude_deg"], "camera_motion.roll_amplitude_deg");
  if (n["oscillation_hz"])
    m.oscillation_hz = r.number(n["oscillation_hz"], "camera_motion.oscillation_hz");
}

void read_effects(const YamlReader& r, const YAML::Node& n, ImageEffects& fx) {
  r.expect_map(n, "effects",
               {"exposure_steps", "vignetting", "right_shift_y_px", "jpeg_quality",
                "exposure_time_s"});
  if (n["exposure_time_s"])
    fx.exposure_time_s = r.number(n["exposure_time_s"], "effects.exposure_time_s");
  if (n["vignetting"]) fx.vignetting = r.number(n["vignetting"], "effects.vignetting");
  if (n["right_shift_y_px"])
    fx.right_shift_y_px = r.number(n["right_shift_y_px"], "effects.right_shift_y_px");
  if (n["jpeg_quality"]) fx.jpeg_quality = r.integer(n["jpeg_quality"], "effects.jpeg_quality");
  if (const YAML::Node steps = n["exposure_steps"]) {
    if (!steps.IsSequence()) r.fail(steps, "effects.exposure_steps", "expected a list");
    fx.exposure_steps.clear();
    for (std::size_t i = 0; i < steps.size(); ++i) {
      const std::string f = "effects.exposure_steps[" + std::to_string(i) + "]";
      r.expect_map(steps[i], f, {"from_s", "gain"});
      ExposureStep step;
      if (steps[i]["from_s"]) step.from_s = r.number(steps[i]["from_s"], f + ".from_s");
      if (steps[i]["gain"]) step.gain = r.number(steps[i]["gain"], f + ".gain");
      fx.exposure_steps.push_back(step);
    }
  }
}

std::vector<AccelerationPhase> read_phases(const YamlReader& r, const YAML::Node& phases,
                                           const std::string& field) {
  if (!phases.IsSequence()) r.fail(phases, field, "expected a list");
  std::vector<AccelerationPhase> out;
  for (std::size_t i = 0; i < phases.size(); ++i) {
    const std::string f = field + "[" + std::to_string(i) + "]";
    r.expect_map(phases[i], f, {"from_s", "acceleration_mps2"});
    AccelerationPhase ph;
    if (phases[i]["from_s"]) ph.from_s = r.number(phases[i]["from_s"], f + ".from_s");
    if (phases[i]["acceleration_mps2"])
      ph.acceleration_mps2 = r.vec3(phases[i]["acceleration_mps2"], f + ".acceleration_mps2");
    out.push_back(ph);
  }
  return out;
}

TextureKind read_texture(const YamlReader& r, const YAML::Node& n, const std::string& field) {
  const std::string name = r.text(n, field);
  try {
    return texture_kind(name);
  } catch (const core::InputError& e) {
    r.fail(n, field, e.what());
  }
}

void read_shadows(const YamlReader& r, const YAML::Node& n, Shadows& sh) {
  r.expect_map(n, "shadows", {"to_light", "casters"});
  if (n["to_light"]) sh.to_light = r.vec3(n["to_light"], "shadows.to_light");
  if (const YAML::Node casters = n["casters"]) {
    if (!casters.IsSequence()) r.fail(casters, "shadows.casters", "expected a list");
    sh.casters.clear();
    for (std::size_t i = 0; i < casters.size(); ++i) {
      const std::string f = "shadows.casters[" + std::to_string(i) + "]";
      const YAML::Node c = casters[i];
      r.expect_map(c, f, {"position_m", "velocity_mps", "radius_m", "darkness"});
      ShadowCaster caster;
      if (c["position_m"]) caster.position_m = r.vec3(c["position_m"], f + ".position_m");
      if (c["velocity_mps"]) caster.velocity_mps = r.vec3(c["velocity_mps"], f + ".velocity_mps");
      if (c["radius_m"]) caster.radius_m = r.number(c["radius_m"], f + ".radius_m");
      if (c["darkness"]) caster.darkness = r.number(c["darkness"], f + ".darkness");
      sh.casters.push_back(caster);
    }
  }
}

/// The scene a `random: {seed: S}` key names.
Scenario read_random_base(const YamlReader& r, const YAML::Node& n) {
  r.expect_map(n, "random", {"seed"});
  if (!n["seed"]) r.fail(n, "random.seed", "missing (random: {seed: S})");
  return random_scenario(r.seed(n["seed"], "random.seed"));
}

Box read_box(const YamlReader& r, const YAML::Node& n, const std::string& field) {
  r.expect_map(n, field,
               {"id", "size_m", "position_m", "velocity_mps", "accelerations", "texture_seed",
                "texture"});
  Box b;
  if (n["id"]) b.id = r.integer(n["id"], field + ".id");
  if (n["size_m"]) b.size_m = r.vec3(n["size_m"], field + ".size_m");
  if (n["position_m"]) b.position_m = r.vec3(n["position_m"], field + ".position_m");
  if (n["velocity_mps"]) b.velocity_mps = r.vec3(n["velocity_mps"], field + ".velocity_mps");
  if (n["texture_seed"]) b.texture_seed = r.seed(n["texture_seed"], field + ".texture_seed");
  if (n["texture"]) b.texture = read_texture(r, n["texture"], field + ".texture");
  if (n["accelerations"])
    b.accelerations = read_phases(r, n["accelerations"], field + ".accelerations");
  return b;
}

Scenario read_scenario(const YamlReader& r, const YAML::Node& root, const std::string& path) {
  if (root.IsNull()) r.fail(root, "(document)", "the file is empty");
  r.expect_map(root, "",
               {"name", "description", "frames", "camera", "height_m", "ego_velocity_mps",
                "ego_follows_heading", "ego_accelerations", "camera_motion", "platform",
                "background_z_m", "background_height_m", "ground_seed", "background_seed",
                "ground_texture", "background_texture", "shadows",
                "noise_sigma", "right_gain", "noise_seed", "edge_samples", "effects", "envelope",
                "min_area_px", "obstacles", "random"});
  Scenario s = root["random"] ? read_random_base(r, root["random"]) : Scenario{};
  if (!root["random"]) s.name = std::filesystem::path(path).stem().string();
  if (root["name"]) s.name = r.text(root["name"], "name");
  if (root["description"]) s.description = r.text(root["description"], "description");
  if (root["frames"]) s.frames = r.integer(root["frames"], "frames");
  if (root["camera"]) read_camera(r, root["camera"], s.camera);
  if (root["height_m"]) s.height_m = r.number(root["height_m"], "height_m");
  if (root["ego_velocity_mps"])
    s.ego_velocity_mps = r.vec3(root["ego_velocity_mps"], "ego_velocity_mps");
  if (root["ego_follows_heading"])
    s.ego_follows_heading = r.boolean(root["ego_follows_heading"], "ego_follows_heading");
  if (root["ego_accelerations"])
    s.ego_accelerations = read_phases(r, root["ego_accelerations"], "ego_accelerations");
  if (root["camera_motion"]) read_camera_motion(r, root["camera_motion"], s.camera_motion);
  if (root["platform"]) s.platform = r.text(root["platform"], "platform");
  if (root["background_z_m"]) s.background_z_m = r.number(root["background_z_m"], "background_z_m");
  if (root["background_height_m"])
    s.background_height_m = r.number(root["background_height_m"], "background_height_m");
  if (root["ground_seed"]) s.ground_seed = r.seed(root["ground_seed"], "ground_seed");
  if (root["background_seed"])
    s.background_seed = r.seed(root["background_seed"], "background_seed");
  if (root["ground_texture"])
    s.ground_texture = read_texture(r, root["ground_texture"], "ground_texture");
  if (root["background_texture"])
    s.background_texture = read_texture(r, root["background_texture"], "background_texture");
  if (root["shadows"]) read_shadows(r, root["shadows"], s.shadows);
  if (root["noise_sigma"]) s.noise_sigma = r.number(root["noise_sigma"], "noise_sigma");
  if (root["right_gain"]) s.right_gain = r.number(root["right_gain"], "right_gain");
  if (root["noise_seed"]) s.noise_seed = r.seed(root["noise_seed"], "noise_seed");
  if (root["edge_samples"]) s.edge_samples = r.integer(root["edge_samples"], "edge_samples");
  if (root["effects"]) read_effects(r, root["effects"], s.effects);
  if (root["envelope"]) read_envelope(r, root["envelope"], s.envelope);
  if (root["min_area_px"]) s.min_area_px = r.integer(root["min_area_px"], "min_area_px");
  if (const YAML::Node obstacles = root["obstacles"]) {
    if (!obstacles.IsSequence() && !obstacles.IsNull())
      r.fail(obstacles, "obstacles", "expected a list of boxes");
    s.obstacles.clear();
    for (std::size_t i = 0; i < obstacles.size(); ++i)
      s.obstacles.push_back(
          read_box(r, obstacles[i], "obstacles[" + std::to_string(i) + "]"));
  }
  return s;
}

}  // namespace

namespace {

/// Walks `phases` (piecewise-constant acceleration, none before the first phase) from time 0,
/// at velocity v then, to time t_s: calls segment(v, a, t0, t1) for each stretch [t0, t1] of
/// constant acceleration, v the velocity at t0 and a null while coasting. Returns the velocity
/// at t_s.
template <typename Segment>
cv::Vec3d walk_phases(const std::vector<AccelerationPhase>& phases, double t_s, cv::Vec3d v,
                      Segment&& segment) {
  double t = 0.0;  // v holds the velocity at time t
  for (std::size_t i = 0; i < phases.size(); ++i) {
    const AccelerationPhase& ph = phases[i];
    if (ph.from_s >= t_s) break;
    if (ph.from_s > t) {  // coast from t to the phase start
      segment(v, nullptr, t, ph.from_s);
      t = ph.from_s;
    }
    const double end = i + 1 < phases.size() ? std::min(t_s, phases[i + 1].from_s) : t_s;
    if (end > t) {
      segment(v, &ph.acceleration_mps2, t, end);
      v += ph.acceleration_mps2 * (end - t);
      t = end;
    }
  }
  segment(v, nullptr, t, t_s);
  return v;
}

/// Position and velocity after moving from (p, v) at time 0 to time t_s under `phases`.
void integrate_phases(const std::vector<AccelerationPhase>& phases, double t_s, cv::Vec3d& p,
                      cv::Vec3d& v) {
  v = walk_phases(phases, t_s, v,
                  [&p](const cv::Vec3d& u, const cv::Vec3d* a, double t0, double t1) {
                    const double span = t1 - t0;
                    p += a ? u * span + *a * (0.5 * span * span) : u * span;
                  });
}

/// The integral over [a, b] of R_y(w tau) (u + k (tau - a)) d tau, w != 0 (R_y as in
/// camera_rotation: it turns +Z towards +X), in closed form.
cv::Vec3d turned_integral(double w, const cv::Vec3d& u, const cv::Vec3d& k, double a, double b) {
  const double sa = std::sin(w * a), sb = std::sin(w * b);
  const double ca = std::cos(w * a), cb = std::cos(w * b);
  const double span = b - a;
  const double c0 = (sb - sa) / w, s0 = (ca - cb) / w;  // integrals of cos, sin
  const double c1 = span * sb / w + (cb - ca) / (w * w);   // of (tau - a) cos
  const double s1 = -span * cb / w + (sb - sa) / (w * w);  // of (tau - a) sin
  return {u[0] * c0 + u[2] * s0 + k[0] * c1 + k[2] * s1, u[1] * span + k[1] * 0.5 * span * span,
          -u[0] * s0 + u[2] * c0 - k[0] * s1 + k[2] * c1};
}

double yaw_rate_rad(const Scenario& s) { return s.camera_motion.yaw_rate_dps * CV_PI / 180.0; }

}  // namespace

const std::vector<std::string>& texture_kind_names() {
  static const std::vector<std::string> kNames = {"noise", "low", "tiles", "stripes", "clutter"};
  return kNames;
}

TextureKind texture_kind(const std::string& name) {
  const auto& names = texture_kind_names();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<TextureKind>(i);
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
  throw core::InputError("unknown texture '" + name + "' (known: " + list + ")");
}

cv::Vec3d box_position(const Box& box, double t_s) {
  cv::Vec3d p = box.position_m, v = box.velocity_mps;
  integrate_phases(box.accelerations, t_s, p, v);
  return p;
}

cv::Vec3d box_velocity(const Box& box, double t_s) {
  return walk_phases(box.accelerations, t_s, box.velocity_mps,
                     [](const cv::Vec3d&, const cv::Vec3d*, double, double) {});
}

cv::Matx33d camera_rotation(const CameraMotion& m, double t_s) {
  constexpr double kDeg = CV_PI / 180.0;
  const double phase = 2.0 * CV_PI * m.oscillation_hz * t_s;
  const double yaw = m.yaw_rate_dps * kDeg * t_s;
  const double pitch = (m.pitch_deg + m.pitch_amplitude_deg * std::sin(phase)) * kDeg;
  const double roll = (m.roll_deg + m.roll_amplitude_deg * std::cos(phase)) * kDeg;
  const double cy = std::cos(yaw), sy = std::sin(yaw);
  const double cp = std::cos(pitch), sp = std::sin(pitch);
  const double cr = std::cos(roll), sr = std::sin(roll);
  // R_y turns +Z towards +X; R_x with positive pitch turns +Z towards -Y (up, y is down).
  const cv::Matx33d ry(cy, 0, sy, 0, 1, 0, -sy, 0, cy);
  const cv::Matx33d rx(1, 0, 0, 0, cp, -sp, 0, sp, cp);
  const cv::Matx33d rz(cr, -sr, 0, sr, cr, 0, 0, 0, 1);
  return ry * rx * rz;
}

cv::Vec3d ego_heading_velocity(const Scenario& s, double t_s) {
  return walk_phases(s.ego_accelerations, t_s, s.ego_velocity_mps,
                     [](const cv::Vec3d&, const cv::Vec3d*, double, double) {});
}

cv::Vec3d ego_velocity(const Scenario& s, double t_s) {
  const cv::Vec3d v = ego_heading_velocity(s, t_s);
  const double w = yaw_rate_rad(s);
  if (!s.ego_follows_heading || w == 0.0) return v;
  const double c = std::cos(w * t_s), sn = std::sin(w * t_s);
  return {c * v[0] + sn * v[2], v[1], -sn * v[0] + c * v[2]};
}

cv::Vec3d ego_position(const Scenario& s, double t_s) {
  const double w = yaw_rate_rad(s);
  if (!s.ego_follows_heading || w == 0.0) {
    cv::Vec3d p(0, 0, 0), v = s.ego_velocity_mps;
    integrate_phases(s.ego_accelerations, t_s, p, v);
    return p;
  }
  // Phase by phase: within one the heading-frame velocity is linear in time.
  cv::Vec3d p(0, 0, 0);
  walk_phases(s.ego_accelerations, t_s, s.ego_velocity_mps,
              [&](const cv::Vec3d& u, const cv::Vec3d* a, double t0, double t1) {
                p += turned_integral(w, u, a ? *a : cv::Vec3d(0, 0, 0), t0, t1);
              });
  return p;
}

cv::Vec3d ego_coasting_position(const Scenario& s, double t_s, double tau_s) {
  if (s.ego_accelerations.empty()) return ego_position(s, t_s + tau_s);
  const cv::Vec3d from = ego_position(s, t_s);
  const double w = yaw_rate_rad(s);
  if (!s.ego_follows_heading || w == 0.0) return from + ego_velocity(s, t_s) * tau_s;
  return from +
         turned_integral(w, ego_heading_velocity(s, t_s), cv::Vec3d(0, 0, 0), t_s, t_s + tau_s);
}

std::vector<std::string> validate(const Scenario& s) {
  std::vector<std::string> out = core::validate(s.camera);
  Checker c(out);
  c.require(s.frames >= 2, "frames", s.frames, "must be >= 2");
  c.require(std::isfinite(s.height_m) && s.height_m > 0, "height_m", s.height_m, "must be > 0");
  c.require(finite(s.ego_velocity_mps), "ego_velocity_mps", to_text(s.ego_velocity_mps),
            "must be finite");
  c.require(std::isfinite(s.background_z_m) && s.background_z_m > 0, "background_z_m",
            s.background_z_m, "must be > 0");
  c.require(std::isfinite(s.background_height_m) && s.background_height_m > 0,
            "background_height_m", s.background_height_m, "must be > 0");
  c.require(std::isfinite(s.noise_sigma) && s.noise_sigma >= 0, "noise_sigma", s.noise_sigma,
            "must be >= 0");
  c.require(std::isfinite(s.right_gain) && s.right_gain > 0, "right_gain", s.right_gain,
            "must be > 0");
  c.require(s.edge_samples >= 1 && s.edge_samples <= 8, "edge_samples", s.edge_samples,
            "must be in 1..8");
  c.require(s.min_area_px >= 0, "min_area_px", s.min_area_px, "must be >= 0");
  const CameraMotion& m = s.camera_motion;
  c.require(std::isfinite(m.yaw_rate_dps), "camera_motion.yaw_rate_dps", m.yaw_rate_dps,
            "must be finite");
  c.require(std::isfinite(m.pitch_deg) && std::abs(m.pitch_deg) <= 45, "camera_motion.pitch_deg",
            m.pitch_deg, "must be in -45..45");
  c.require(std::isfinite(m.roll_deg) && std::abs(m.roll_deg) <= 45, "camera_motion.roll_deg",
            m.roll_deg, "must be in -45..45");
  c.require(std::isfinite(m.pitch_amplitude_deg) && std::abs(m.pitch_amplitude_deg) <= 45,
            "camera_motion.pitch_amplitude_deg", m.pitch_amplitude_deg, "must be in -45..45");
  c.require(std::isfinite(m.roll_amplitude_deg) && std::abs(m.roll_amplitude_deg) <= 45,
            "camera_motion.roll_amplitude_deg", m.roll_amplitude_deg, "must be in -45..45");
  c.require(std::isfinite(m.oscillation_hz) && m.oscillation_hz > 0,
            "camera_motion.oscillation_hz", m.oscillation_hz, "must be > 0");
  if (!s.platform.empty()) {
    bool known = false;
    std::string list;
    for (const auto& n : core::platform_names()) {
      known = known || n == s.platform;
      list += (list.empty() ? "" : ", ") + n;
    }
    c.require(known, "platform", s.platform, ("must be one of: " + list).c_str());
  }
  const ImageEffects& fx = s.effects;
  c.require(std::isfinite(fx.vignetting) && fx.vignetting >= 0 && fx.vignetting <= 0.9,
            "effects.vignetting", fx.vignetting, "must be in 0..0.9");
  c.require(std::isfinite(fx.right_shift_y_px) && std::abs(fx.right_shift_y_px) <= 2,
            "effects.right_shift_y_px", fx.right_shift_y_px, "must be in -2..2");
  c.require(fx.jpeg_quality >= 0 && fx.jpeg_quality <= 100, "effects.jpeg_quality",
            fx.jpeg_quality, "must be in 0..100 (0 = none)");
  for (std::size_t k = 0; k < fx.exposure_steps.size(); ++k) {
    const ExposureStep& step = fx.exposure_steps[k];
    const std::string f = "effects.exposure_steps[" + std::to_string(k) + "]";
    c.require(std::isfinite(step.from_s) && step.from_s >= 0 &&
                  (k == 0 || step.from_s > fx.exposure_steps[k - 1].from_s),
              f + ".from_s", step.from_s, "must be >= 0 and increase from step to step");
    c.require(std::isfinite(step.gain) && step.gain > 0, f + ".gain", step.gain, "must be > 0");
  }
  c.require(std::isfinite(fx.exposure_time_s) && fx.exposure_time_s >= 0 &&
                fx.exposure_time_s <= 0.1,
            "effects.exposure_time_s", fx.exposure_time_s, "must be in 0..0.1");
  const auto check_phases = [&](const std::vector<AccelerationPhase>& phases,
                                const std::string& field) {
    for (std::size_t k = 0; k < phases.size(); ++k) {
      const AccelerationPhase& ph = phases[k];
      const std::string f = field + "[" + std::to_string(k) + "]";
      c.require(std::isfinite(ph.from_s) && ph.from_s >= 0 &&
                    (k == 0 || ph.from_s > phases[k - 1].from_s),
                f + ".from_s", ph.from_s, "must be >= 0 and increase from phase to phase");
      c.require(finite(ph.acceleration_mps2), f + ".acceleration_mps2",
                to_text(ph.acceleration_mps2), "must be finite");
    }
  };
  check_phases(s.ego_accelerations, "ego_accelerations");
  c.require(finite(s.shadows.to_light) && s.shadows.to_light[1] < 0, "shadows.to_light",
            to_text(s.shadows.to_light), "must be finite and point up (y < 0)");
  for (std::size_t k = 0; k < s.shadows.casters.size(); ++k) {
    const ShadowCaster& sc = s.shadows.casters[k];
    const std::string f = "shadows.casters[" + std::to_string(k) + "]";
    c.require(finite(sc.position_m), f + ".position_m", to_text(sc.position_m), "must be finite");
    c.require(finite(sc.velocity_mps), f + ".velocity_mps", to_text(sc.velocity_mps),
              "must be finite");
    c.require(std::isfinite(sc.radius_m) && sc.radius_m > 0, f + ".radius_m", sc.radius_m,
              "must be > 0");
    c.require(std::isfinite(sc.darkness) && sc.darkness >= 0 && sc.darkness <= 0.95,
              f + ".darkness", sc.darkness, "must be in 0..0.95");
  }
  for (const auto& e : core::validate(s.envelope)) out.push_back(e);
  std::set<int> ids;
  for (std::size_t i = 0; i < s.obstacles.size(); ++i) {
    const Box& b = s.obstacles[i];
    const std::string field = "obstacles[" + std::to_string(i) + "]";
    c.require(b.id >= 1 && b.id <= 65535, field + ".id", b.id, "must be in 1..65535");
    c.require(ids.insert(b.id).second, field + ".id", b.id, "must be unique");
    c.require(finite(b.size_m) && b.size_m[0] > 0 && b.size_m[1] > 0 && b.size_m[2] > 0,
              field + ".size_m", to_text(b.size_m), "each must be > 0");
    c.require(finite(b.position_m), field + ".position_m", to_text(b.position_m),
              "must be finite");
    c.require(finite(b.velocity_mps), field + ".velocity_mps", to_text(b.velocity_mps),
              "must be finite");
    check_phases(b.accelerations, field + ".accelerations");
  }
  return out;
}

Scenario load_scenario_file(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw core::InputError(path + ": scenario file not found");
  const std::string text = core::read_yaml_text(path, path);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw core::InputError(path + ":" + std::to_string(e.mark.line + 1) +
                           ": YAML syntax error: " + e.msg);
  } catch (const YAML::Exception& e) {
    throw core::InputError(path + ": cannot read scenario: " + e.msg);
  }
  const YamlReader reader(path);
  Scenario s = read_scenario(reader, root, path);
  core::throw_if_invalid(validate(s), path + ": invalid scenario");
  return s;
}

Scenario resolve_scenario(const std::string& name_or_path) {
  for (const auto& name : builtin_scenario_names())
    if (name == name_or_path) return builtin_scenario(name);
  std::error_code ec;
  if (std::filesystem::exists(name_or_path, ec)) return load_scenario_file(name_or_path);
  std::string list;
  for (const auto& name : builtin_scenario_names()) list += (list.empty() ? "" : ", ") + name;
  throw core::InputError("unknown scenario '" + name_or_path +
                         "' (not a file; built-in: " + list + ")");
}

std::string to_yaml(const Scenario& s) {
  YAML::Emitter e;
  const auto vec = [&e](const cv::Vec3d& v) {
    e << YAML::Flow << YAML::BeginSeq << to_text(v[0]) << to_text(v[1]) << to_text(v[2])
      << YAML::EndSeq;
  };
  const auto phases = [&](const std::vector<AccelerationPhase>& list) {
    e << YAML::BeginSeq;
    for (const AccelerationPhase& ph : list) {
      e << YAML::Flow << YAML::BeginMap;
      e << YAML::Key << "from_s" << YAML::Value << to_text(ph.from_s);
      e << YAML::Key << "acceleration_mps2" << YAML::Value;
      vec(ph.acceleration_mps2);
      e << YAML::EndMap;
    }
    e << YAML::EndSeq;
  };
  e << YAML::BeginMap;
  e << YAML::Key << "name" << YAML::Value << YAML::DoubleQuoted << s.name;
  e << YAML::Key << "description" << YAML::Value << YAML::DoubleQuoted << s.description;
  e << YAML::Key << "frames" << YAML::Value << s.frames;
  e << YAML::Key << "camera" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "width" << YAML::Value << s.camera.width;
  e << YAML::Key << "height" << YAML::Value << s.camera.height;
  e << YAML::Key << "focal_px" << YAML::Value << to_text(s.camera.focal_px);
  e << YAML::Key << "baseline_m" << YAML::Value << to_text(s.camera.baseline_m);
  e << YAML::Key << "cx" << YAML::Value << to_text(s.camera.cx);
  e << YAML::Key << "cy" << YAML::Value << to_text(s.camera.cy);
  e << YAML::Key << "fps" << YAML::Value << to_text(s.camera.fps);
  e << YAML::EndMap;
  e << YAML::Key << "height_m" << YAML::Value << to_text(s.height_m);
  e << YAML::Key << "ego_velocity_mps" << YAML::Value;
  vec(s.ego_velocity_mps);
  e << YAML::Key << "ego_follows_heading" << YAML::Value << s.ego_follows_heading;
  if (!s.ego_accelerations.empty()) {
    e << YAML::Key << "ego_accelerations" << YAML::Value;
    phases(s.ego_accelerations);
  }
  e << YAML::Key << "camera_motion" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "yaw_rate_dps" << YAML::Value << to_text(s.camera_motion.yaw_rate_dps);
  e << YAML::Key << "pitch_deg" << YAML::Value << to_text(s.camera_motion.pitch_deg);
  e << YAML::Key << "roll_deg" << YAML::Value << to_text(s.camera_motion.roll_deg);
  e << YAML::Key << "pitch_amplitude_deg" << YAML::Value
    << to_text(s.camera_motion.pitch_amplitude_deg);
  e << YAML::Key << "roll_amplitude_deg" << YAML::Value
    << to_text(s.camera_motion.roll_amplitude_deg);
  e << YAML::Key << "oscillation_hz" << YAML::Value << to_text(s.camera_motion.oscillation_hz);
  e << YAML::EndMap;
  e << YAML::Key << "platform" << YAML::Value << YAML::DoubleQuoted << s.platform;
  e << YAML::Key << "background_z_m" << YAML::Value << to_text(s.background_z_m);
  e << YAML::Key << "background_height_m" << YAML::Value << to_text(s.background_height_m);
  e << YAML::Key << "ground_seed" << YAML::Value << s.ground_seed;
  e << YAML::Key << "background_seed" << YAML::Value << s.background_seed;
  const auto kind = [](TextureKind k) { return texture_kind_names()[static_cast<std::size_t>(k)]; };
  e << YAML::Key << "ground_texture" << YAML::Value << kind(s.ground_texture);
  e << YAML::Key << "background_texture" << YAML::Value << kind(s.background_texture);
  if (!s.shadows.casters.empty()) {
    e << YAML::Key << "shadows" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "to_light" << YAML::Value;
    vec(s.shadows.to_light);
    e << YAML::Key << "casters" << YAML::Value << YAML::BeginSeq;
    for (const ShadowCaster& c : s.shadows.casters) {
      e << YAML::BeginMap;
      e << YAML::Key << "position_m" << YAML::Value;
      vec(c.position_m);
      e << YAML::Key << "velocity_mps" << YAML::Value;
      vec(c.velocity_mps);
      e << YAML::Key << "radius_m" << YAML::Value << to_text(c.radius_m);
      e << YAML::Key << "darkness" << YAML::Value << to_text(c.darkness);
      e << YAML::EndMap;
    }
    e << YAML::EndSeq;
    e << YAML::EndMap;
  }
  e << YAML::Key << "noise_sigma" << YAML::Value << to_text(s.noise_sigma);
  e << YAML::Key << "right_gain" << YAML::Value << to_text(s.right_gain);
  e << YAML::Key << "noise_seed" << YAML::Value << s.noise_seed;
  e << YAML::Key << "edge_samples" << YAML::Value << s.edge_samples;
  if (s.effects.any() || s.effects.exposure_time_s != 0.0) {
    e << YAML::Key << "effects" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "exposure_steps" << YAML::Value << YAML::BeginSeq;
    for (const ExposureStep& step : s.effects.exposure_steps) {
      e << YAML::Flow << YAML::BeginMap;
      e << YAML::Key << "from_s" << YAML::Value << to_text(step.from_s);
      e << YAML::Key << "gain" << YAML::Value << to_text(step.gain);
      e << YAML::EndMap;
    }
    e << YAML::EndSeq;
    e << YAML::Key << "vignetting" << YAML::Value << to_text(s.effects.vignetting);
    e << YAML::Key << "right_shift_y_px" << YAML::Value << to_text(s.effects.right_shift_y_px);
    e << YAML::Key << "jpeg_quality" << YAML::Value << s.effects.jpeg_quality;
    e << YAML::Key << "exposure_time_s" << YAML::Value << to_text(s.effects.exposure_time_s);
    e << YAML::EndMap;
  }
  e << YAML::Key << "envelope" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "half_width_m" << YAML::Value << to_text(s.envelope.half_width_m);
  e << YAML::Key << "y_top_m" << YAML::Value << to_text(s.envelope.y_top_m);
  e << YAML::Key << "y_bottom_m" << YAML::Value << to_text(s.envelope.y_bottom_m);
  e << YAML::Key << "z_contact_m" << YAML::Value << to_text(s.envelope.z_contact_m);
  e << YAML::Key << "horizon_s" << YAML::Value << to_text(s.envelope.horizon_s);
  e << YAML::EndMap;
  e << YAML::Key << "min_area_px" << YAML::Value << s.min_area_px;
  e << YAML::Key << "obstacles" << YAML::Value << YAML::BeginSeq;
  for (const Box& b : s.obstacles) {
    e << YAML::BeginMap;
    e << YAML::Key << "id" << YAML::Value << b.id;
    e << YAML::Key << "size_m" << YAML::Value;
    vec(b.size_m);
    e << YAML::Key << "position_m" << YAML::Value;
    vec(b.position_m);
    e << YAML::Key << "velocity_mps" << YAML::Value;
    vec(b.velocity_mps);
    if (!b.accelerations.empty()) {
      e << YAML::Key << "accelerations" << YAML::Value;
      phases(b.accelerations);
    }
    e << YAML::Key << "texture_seed" << YAML::Value << b.texture_seed;
    e << YAML::Key << "texture" << YAML::Value << kind(b.texture);
    e << YAML::EndMap;
  }
  e << YAML::EndSeq;
  e << YAML::EndMap;
  return std::string(e.c_str()) + "\n";
}

void save_scenario_file(const Scenario& s, const std::string& path) {
  std::ofstream out(path);
  out << to_yaml(s);
  if (!out.flush()) throw core::InputError(path + ": cannot write scenario file");
}

}  // namespace sg::sim
