#pragma once
/// Platform presets: the detector settings a kind of platform needs (its safety envelope, the
/// stereo range that reaches as far as it must look). A user selects one with `--platform NAME`
/// or the config key `platform: NAME`; a scenario names the platform it is made for.
#include <string>
#include <vector>

#include "sg/core/params.hpp"

namespace sg::core {

/// "robot" (the defaults), "walker", "car", "drone".
std::vector<std::string> platform_names();

/// The safety envelope of a platform (camera frame, m, s). Throws InputError for an unknown name.
///  * robot: the DetectorParams defaults, |X| <= 0.5, -1.0 <= Y <= 1.0, contact 0.5 m.
///  * walker (camera on the chest, about 1.3 m up): |X| <= 0.35, -0.7 <= Y <= 1.1 (head top to
///    20 cm above the ground), contact 0.4 m.
///  * car (camera behind the windscreen, about 1.3 m up, 2 m behind the front bumper):
///    |X| <= 1.0, -0.4 <= Y <= 1.1, contact 2.0 m.
///  * drone (a small multicopter, the camera at its centre, flying at up to 6 m/s): |X| <= 0.6,
///    -0.4 <= Y <= 0.4 (rotors and a margin, the ground below stays out), contact 1.0 m.
Envelope platform_envelope(const std::string& name);

/// Sets the fields a platform governs, whatever they held before (so presets can be applied
/// over one another): envelope; bm.num_disparities; stereo.z_max_m; scene_flow.z_max_m,
/// scene_flow.ground.z_max_m; scene_flow.predict_turn. robot and walker keep the defaults (64
/// disparities, 12 / 20 / 12 m, the straight line ahead); car: 128 disparities (nearest depth
/// f*B/128, 1.4 m at f 600 px, B 0.30 m), 40 / 60 / 40 m (a stopped car is 3 s away at 32 m at
/// 10 m/s), and the arc it drives through a bend; drone: 25 / 30 m (3 s ahead at 6 m/s plus the
/// contact distance), the straight line ahead. "" leaves `params` as it is.
/// Throws InputError naming the known platforms for an unknown name.
void apply_platform(const std::string& name, DetectorParams& params);

/// The image size, frame rate and focal length x baseline that the defaults were written for
/// (the simulator's default camera): pixel sizes and frame gaps scale from it.
inline constexpr int kReferenceWidth = 640;
inline constexpr int kReferenceHeight = 480;
inline constexpr double kReferenceFps = 30.0;
/// The largest disparity range derived from a camera, px: beyond it matching costs grow and the
/// left image loses that many columns.
inline constexpr int kMaxDerivedDisparities = 256;
/// The largest matching block derived from a camera, px: it fits the fast matcher's 16-bit sums
/// at prefilter caps up to 63 (DESIGN 2.1).
inline constexpr int kMaxDerivedBlock = 21;

/// What adapt_to_camera set, for the run's first line and its warnings.
struct CameraFit {
  double near_m = 0.0;  ///< the nearest depth the disparity range measures, f B / (range - 1)
  double far_m = 0.0;   ///< the farthest depth any detection counts (the mode's z_max_m)
  /// Set when the range was capped short of the contact distance: a line naming the nearest
  /// measurable distance, for the user.
  std::string warning;
};

/// Fits the defaults that depend on the camera to `camera`, for the envelope `params` holds
/// (DESIGN 4.1, "defaults derived from the camera"). Apply it after the platform preset and before
/// a config file and flags, which still override each value:
///  * bm.num_disparities: the smallest multiple of 16 with f B / (d - 1) <= z_contact, so that the
///    matcher still measures at the contact plane, capped at kMaxDerivedDisparities and below the
///    image width (with `warning` set);
///  * pixel areas (signal.min_area_px, signal.region_min_px) scale with the image area, and
///    lengths (scene_flow.edge_margin_px) with its width, from kReferenceWidth x kReferenceHeight;
///  * bm.block_size grows with the width above kReferenceWidth, so that the block keeps its angle
///    (the odd size at or below, up to kMaxDerivedBlock; 21 px at 1280 wide); narrower images
///    keep it;
///  * frame counts keep their time at the camera's rate (written for kReferenceFps), at least one
///    frame each: the gaps (stereo.gaps, scene_flow.gaps; a 20-frame gap at 30 fps is 10 frames
///    at 15 fps) and the hysteresis (signal.on_k, on_n, off_m, severity_off_frames).
///    signal.confirm_frames stays: it counts observations, not time.
CameraFit adapt_to_camera(DetectorParams& params, const Camera& camera);

/// The nearest and farthest depth `params` measures with `camera` (CameraFit without a warning).
CameraFit depth_range(const DetectorParams& params, const Camera& camera);

}  // namespace sg::core
