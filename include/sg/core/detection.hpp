#pragma once
/// What the detector says about one frame.
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

namespace sg::core {

enum class Severity { kNone, kWarning, kDanger };
enum class Steering { kStraight, kLeft, kRight, kStop };

/// "none" / "warning" / "danger".
const char* to_string(Severity s);
/// "straight" / "left" / "right" / "stop".
const char* to_string(Steering s);

struct RegionSignal {
  std::string name;       ///< "left", "centre", "right" for the default three columns
  bool fired = false;     ///< after hysteresis
  int dangerous_px = 0;   ///< dangerous pixels in this region in this frame (before hysteresis)
};

struct Obstacle {
  cv::Rect bbox;                       ///< in left-image pixels
  int pixels = 0;                      ///< dangerous pixels of the blob
  double distance_m = 0.0;             ///< median depth of the blob, m
  std::optional<double> ttc_s;         ///< median time to contact, s
  std::optional<cv::Vec3d> velocity;   ///< mean 3D velocity relative to the camera, m/s (Stereo-Flow)
  int track_id = 0;                    ///< the same obstacle keeps its id across frames; 0 = untracked
  /// Consecutive frames its track has been seen in with a distance that agrees with its motion,
  /// this one included (vision/tracking.hpp); 0 = untracked. Below signal.confirm_frames the
  /// blob raises no alarm by itself.
  int seen_frames = 0;
  /// Speed at which the distance shrinks, m/s, from the fit over the track (vision/tracking.hpp);
  /// when set, distance_m and ttc_s come from that fit too.
  std::optional<double> closing_speed_mps;
  /// distance_m and ttc_s are the track's prediction, not a measurement: the obstacle came nearer
  /// than the matcher's disparity range reaches (vision/tracking.hpp, signal.coast_near_range).
  /// pixels = 0 and bbox = the last measured box when its blob is no longer seen at all.
  bool predicted = false;
};

struct Detection {
  int frame = 0;
  double time_s = 0.0;
  bool signal = false;                  ///< any region fired
  Severity severity = Severity::kNone;  ///< by the smallest obstacle TTC, none when no signal
  Steering steering = Steering::kStraight;
  std::vector<RegionSignal> regions;
  std::vector<Obstacle> obstacles;
  double latency_ms = 0.0;              ///< acquisition to detection, ms
  cv::Mat danger;                       ///< CV_8U mask after clean-up, 255 = dangerous (for overlays)
  /// The frame's maps, only when the run was asked to keep them (pipeline RunOptions::keep_maps,
  /// for --dump): disparity CV_32F px (invalid < 0); backward flow CV_32FC2 px (Stereo-Flow, from
  /// the second frame on). Empty otherwise.
  cv::Mat disparity, flow;
};

}  // namespace sg::core
