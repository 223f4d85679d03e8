#pragma once
/// Detector parameters: plain aggregates with defaults, units in the comments. Validate once at the
/// boundary (CLI, config file, library entry) with validate(); kernels assume valid input.
#include <string>
#include <vector>

#include "sg/core/camera.hpp"

namespace sg::core {

enum class Mode { kStereo, kStereoFlow };
/// "stereo" / "stereo-flow".
const char* to_string(Mode m);
/// Parses "stereo" / "stereo-flow"; throws InputError otherwise.
Mode parse_mode(const std::string& text);

/// OpenCV StereoBM settings (DESIGN 2.1).
struct BmParams {
  int min_disparity = 0;        ///< px
  int num_disparities = 64;     ///< px, positive multiple of 16
  int block_size = 11;          ///< px, odd, 5..255
  int prefilter_cap = 31;       ///< 1..63
  int texture_threshold = 10;   ///< >= 0; low-texture blocks become invalid
  int uniqueness_ratio = 15;    ///< percent, >= 0
  int speckle_window = 100;     ///< px, 0 disables the speckle filter
  int speckle_range = 2;        ///< px (scaled by 16 internally), >= 0
  int lr_max_diff = -1;         ///< px, left-right check tolerance; -1 disables
};

/// The space the platform occupies, in camera coordinates (DESIGN 3.2). Defaults: a small robot.
struct Envelope {
  double half_width_m = 0.5;  ///< |X| <= half_width_m
  double y_top_m = -1.0;      ///< top of the envelope (y down), m
  double y_bottom_m = 1.0;    ///< bottom of the envelope, m; the ground lies below
  double z_contact_m = 0.5;   ///< depth at which a point touches the platform, m
  double horizon_s = 3.0;     ///< warn about contacts within this time, s
};

/// Stereo-mode pixel labelling (DESIGN 3.1): depth decreases.
struct StereoLabelParams {
  /// Frame gaps k compared: D_i against D_{i-k}. k = 1 is the thesis; larger k catch slow
  /// (far) approaches whose per-frame disparity change is below the matcher's noise. At 30 fps
  /// gap 15 spans 0.5 s: a point with TTC <= 3 s at Z m changes by >= f*B*0.5/(3 Z) px over it
  /// (1 px at 10 m for f*B = 60), so min_delta_d_px = 1 still sees it (simulated head-on:
  /// recall 1.0, lead 2.98 s; static and receding scenes: no alarm frame).
  std::vector<int> gaps = {1, 5, 15};
  double z_max_m = 12.0;        ///< ignore points farther than this, m
  /// D_i - D_{i-k} must reach this, px. Well above BM's sub-pixel noise (0.1-0.3 px): with 0.5 the
  /// simulated receding box raised alarms.
  double min_delta_d_px = 1.0;
  /// D_i <= max_growth * D_{i-k}, else the gap is ignored for that pixel: a depth that more than
  /// halves within the gap is an object edge sweeping over the pixel, not motion (an approach that
  /// fast is caught by the smaller gaps). 0 disables; otherwise > 1.
  double max_growth = 2.0;
  /// Skip points outside the envelope's vertical band (ground, overhead): y_top <= Y <= y_bottom.
  bool use_envelope_band = true;
};

/// From dangerous pixels to signals (DESIGN 3.3).
struct SignalParams {
  int open_size = 3;             ///< morphological opening kernel, px (odd; 1 disables)
  int min_area_px = 150;         ///< blobs smaller than this are dropped, px
  int region_columns = 3;        ///< left / centre / right
  int region_min_px = 150;       ///< a region is dangerous in a frame above this many px
  int on_k = 2;                  ///< region turns on after on_k of the last on_n frames were dangerous
  int on_n = 3;
  int off_m = 3;                 ///< ... and off after off_m clear frames
  double ttc_danger_s = 1.5;     ///< severity danger when min TTC <= this, s
  double ttc_warning_s = 3.0;    ///< severity warning when min TTC <= this, s
};

/// Everything the detector needs.
struct DetectorParams {
  Mode mode = Mode::kStereo;
  BmParams bm;
  Envelope envelope;
  StereoLabelParams stereo;
  SignalParams signal;
};

/// Every violation as "<section>.<field>=<value>: <rule>"; empty when valid.
std::vector<std::string> validate(const BmParams& p);
std::vector<std::string> validate(const Envelope& p);
std::vector<std::string> validate(const StereoLabelParams& p);
std::vector<std::string> validate(const SignalParams& p);
/// All of the above plus checks against the image size (num_disparities < width, etc.).
std::vector<std::string> validate(const DetectorParams& p, const Camera& camera);

}  // namespace sg::core
