#include "sg/core/platform.hpp"

#include "sg/core/error.hpp"

namespace sg::core {
namespace {

struct Preset {
  const char* name;
  Envelope envelope;
  int num_disparities;
  double stereo_z_max_m;
  double scene_flow_z_max_m;
  double ground_z_max_m;
};

const std::vector<Preset>& presets() {
  static const DetectorParams kDefaults;
  static const std::vector<Preset> kAll = {
      {"robot", kDefaults.envelope, kDefaults.bm.num_disparities, kDefaults.stereo.z_max_m,
       kDefaults.scene_flow.z_max_m, kDefaults.scene_flow.ground.z_max_m},
      {"walker",
       Envelope{.half_width_m = 0.35,
                .y_top_m = -0.7,
                .y_bottom_m = 1.1,
                .z_contact_m = 0.4,
                .horizon_s = 3.0},
       kDefaults.bm.num_disparities, kDefaults.stereo.z_max_m, kDefaults.scene_flow.z_max_m,
       kDefaults.scene_flow.ground.z_max_m},
      {"car",
       Envelope{.half_width_m = 1.0,
                .y_top_m = -0.4,
                .y_bottom_m = 1.1,
                .z_contact_m = 2.0,
                .horizon_s = 3.0},
       128, 40.0, 60.0, 40.0},
  };
  return kAll;
}

const Preset& find(const std::string& name) {
  for (const Preset& p : presets())
    if (name == p.name) return p;
  std::string list;
  for (const Preset& p : presets()) list += (list.empty() ? "" : ", ") + std::string(p.name);
  throw InputError("unknown platform '" + name + "' (known: " + list + ")");
}

}  // namespace

std::vector<std::string> platform_names() {
  std::vector<std::string> names;
  for (const Preset& p : presets()) names.emplace_back(p.name);
  return names;
}

Envelope platform_envelope(const std::string& name) { return find(name).envelope; }

void apply_platform(const std::string& name, DetectorParams& params) {
  if (name.empty()) return;
  const Preset& p = find(name);
  params.envelope = p.envelope;
  params.bm.num_disparities = p.num_disparities;
  params.stereo.z_max_m = p.stereo_z_max_m;
  params.scene_flow.z_max_m = p.scene_flow_z_max_m;
  params.scene_flow.ground.z_max_m = p.ground_z_max_m;
}

}  // namespace sg::core
