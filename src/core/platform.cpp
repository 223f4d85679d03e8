#include "sg/core/platform.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

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
  bool predict_turn;  ///< scene_flow.predict_turn: the platform drives where it heads
};

const std::vector<Preset>& presets() {
  static const DetectorParams kDefaults;
  static const std::vector<Preset> kAll = {
      {"robot", kDefaults.envelope, kDefaults.bm.num_disparities, kDefaults.stereo.z_max_m,
       kDefaults.scene_flow.z_max_m, kDefaults.scene_flow.ground.z_max_m,
       kDefaults.scene_flow.predict_turn},
      {"walker",
       Envelope{.half_width_m = 0.35,
                .y_top_m = -0.7,
                .y_bottom_m = 1.1,
                .z_contact_m = 0.4,
                .horizon_s = 3.0},
       kDefaults.bm.num_disparities, kDefaults.stereo.z_max_m, kDefaults.scene_flow.z_max_m,
       kDefaults.scene_flow.ground.z_max_m, kDefaults.scene_flow.predict_turn},
      {"car",
       Envelope{.half_width_m = 1.0,
                .y_top_m = -0.4,
                .y_bottom_m = 1.1,
                .z_contact_m = 2.0,
                .horizon_s = 3.0},
       128, 40.0, 60.0, 40.0, true},
      {"drone",
       Envelope{.half_width_m = 0.6,
                .y_top_m = -0.4,
                .y_bottom_m = 0.4,
                .z_contact_m = 1.0,
                .horizon_s = 3.0},
       kDefaults.bm.num_disparities, 25.0, 30.0, kDefaults.scene_flow.ground.z_max_m,
       kDefaults.scene_flow.predict_turn},
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
  params.scene_flow.predict_turn = p.predict_turn;
}

}  // namespace sg::core

namespace sg::core {
namespace {

/// `frames` frames at kReferenceFps as frames at `fps`: the same time, at least 1 frame.
int frames_at(int frames, double fps) {
  return std::max(1, static_cast<int>(std::lround(frames * fps / kReferenceFps)));
}

/// Gaps of `gaps` frames at kReferenceFps, as frames at `fps`: the same spans, at least 1 frame,
/// each once, in increasing order.
std::vector<int> gaps_at(const std::vector<int>& gaps, double fps) {
  std::vector<int> out;
  for (int k : gaps) out.push_back(frames_at(k, fps));
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

/// The smallest area a blob can have and still be an obstacle, px, whatever the image size:
/// below it a blob is a few matching windows wide, a mismatch as likely as a surface.
constexpr int kMinAreaFloorPx = 16;

int scaled_area(int area_px, double area_ratio) {
  return std::max(kMinAreaFloorPx, static_cast<int>(std::lround(area_px * area_ratio)));
}

/// `block_px` (odd) for an image `width` px wide: the same angle as at kReferenceWidth, the odd
/// size at or below block_px x width / kReferenceWidth, never smaller than block_px nor larger
/// than kMaxDerivedBlock.
int scaled_block(int block_px, int width) {
  int scaled = static_cast<int>(
      std::lround(block_px * static_cast<double>(width) / kReferenceWidth));
  if (scaled % 2 == 0) --scaled;
  return std::max(block_px, std::min(scaled, kMaxDerivedBlock));
}

}  // namespace

CameraFit depth_range(const DetectorParams& params, const Camera& camera) {
  CameraFit fit;
  const int top = params.bm.min_disparity + params.bm.num_disparities - 1;
  fit.near_m = top > 0 ? camera.depth(top) : 0.0;
  fit.far_m = params.mode == Mode::kStereo ? params.stereo.z_max_m : params.scene_flow.z_max_m;
  return fit;
}

CameraFit adapt_to_camera(DetectorParams& params, const Camera& camera) {
  // The range: the matcher measures disparities min_disparity .. min_disparity + range - 1.
  const double fb = camera.focal_px * camera.baseline_m;
  const double needed = fb / params.envelope.z_contact_m - params.bm.min_disparity + 1.0;
  const int wanted = std::max(16, static_cast<int>(std::ceil(needed / 16.0 - 1e-9)) * 16);
  const int width_cap = std::max(16, (camera.width / 2) / 16 * 16);
  const int cap = std::min(kMaxDerivedDisparities, width_cap);
  params.bm.num_disparities = std::min(wanted, cap);

  const double area_ratio = static_cast<double>(camera.width) * camera.height /
                            (static_cast<double>(kReferenceWidth) * kReferenceHeight);
  params.signal.min_area_px = scaled_area(params.signal.min_area_px, area_ratio);
  params.signal.region_min_px = scaled_area(params.signal.region_min_px, area_ratio);
  params.bm.block_size = scaled_block(params.bm.block_size, camera.width);
  // The margin covers the block's fattening of the foreground (half a block) and the flow's
  // bleeding over edges, which shrinks with the image; it never grows past the default, even
  // where the grown block's half exceeds it (10 px at 1280 wide against a margin of 8).
  const int margin = static_cast<int>(
      std::lround(params.scene_flow.edge_margin_px * static_cast<double>(camera.width) /
                  kReferenceWidth));
  params.scene_flow.edge_margin_px = std::clamp(margin, std::min(params.bm.block_size / 2,
                                                                 params.scene_flow.edge_margin_px),
                                                params.scene_flow.edge_margin_px);

  params.stereo.gaps = gaps_at(params.stereo.gaps, camera.fps);
  params.scene_flow.gaps = gaps_at(params.scene_flow.gaps, camera.fps);
  // The hysteresis' frame counts keep their time too (at least one frame each).
  SignalParams& s = params.signal;
  s.on_n = frames_at(s.on_n, camera.fps);
  s.on_k = std::min(s.on_n, frames_at(s.on_k, camera.fps));
  s.off_m = frames_at(s.off_m, camera.fps);
  s.severity_off_frames = frames_at(s.severity_off_frames, camera.fps);

  CameraFit fit = depth_range(params, camera);
  if (wanted > cap) {
    char line[256];
    std::snprintf(line, sizeof line,
                  "the disparity range is capped at %d px: nothing nearer than %.2f m is measured "
                  "(contact at %.2f m needs %d px)",
                  cap, fit.near_m, params.envelope.z_contact_m, wanted);
    fit.warning = line;
  }
  return fit;
}

}  // namespace sg::core
