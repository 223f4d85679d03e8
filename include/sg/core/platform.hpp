#pragma once
/// Platform presets: the detector settings a kind of platform needs (its safety envelope, the
/// stereo range that reaches as far as it must look). A user selects one with `--platform NAME`
/// or the config key `platform: NAME`; a scenario names the platform it is made for.
#include <string>
#include <vector>

#include "sg/core/params.hpp"

namespace sg::core {

/// "robot" (the defaults), "walker", "car".
std::vector<std::string> platform_names();

/// The safety envelope of a platform (camera frame, m, s). Throws InputError for an unknown name.
///  * robot: the DetectorParams defaults, |X| <= 0.5, -1.0 <= Y <= 1.0, contact 0.5 m.
///  * walker (camera on the chest, about 1.3 m up): |X| <= 0.35, -0.7 <= Y <= 1.1 (head top to
///    20 cm above the ground), contact 0.4 m.
///  * car (camera behind the windscreen, about 1.3 m up, 2 m behind the front bumper):
///    |X| <= 1.0, -0.4 <= Y <= 1.1, contact 2.0 m.
Envelope platform_envelope(const std::string& name);

/// Sets the fields a platform governs, whatever they held before (so presets can be applied
/// over one another): envelope; bm.num_disparities; stereo.z_max_m; scene_flow.z_max_m,
/// scene_flow.ground.z_max_m. robot and walker keep the defaults (64 disparities, 12 / 20 / 12 m);
/// car: 128 disparities (nearest depth f*B/128, 1.4 m at f 600 px, B 0.30 m), 40 / 60 / 40 m
/// (a stopped car is 3 s away at 32 m at 10 m/s). "" leaves `params` as it is.
/// Throws InputError naming the known platforms for an unknown name.
void apply_platform(const std::string& name, DetectorParams& params);

}  // namespace sg::core
