#pragma once
/// Obstacles over time (DESIGN 3.3): the same blob is followed from frame to frame, and its time
/// to contact comes from a straight-line fit of its distance over the last second instead of the
/// median of noisy per-pixel TTCs; severity with hysteresis.
#include <deque>
#include <vector>

#include "sg/core/detection.hpp"
#include "sg/core/params.hpp"

namespace sg::vision {

/// Least-squares line z = a + b (t - t_last) through (t, z) samples; false with fewer than two
/// samples or when every t is equal. distance_now = a (the fit at the last sample's time), m;
/// rate = b, m/s.
bool fit_line(const std::vector<double>& t, const std::vector<double>& z, double& distance_now,
              double& rate);

/// Follows obstacles across frames and replaces each one's distance and TTC by a fit over its
/// track. Frames must come in time order; dropped frames are fine (the fit uses time stamps).
class ObstacleTracker {
 public:
  /// p must be valid; z_contact_m = the envelope's contact depth, m; z_near_limit_m = the
  /// nearest depth the matcher measures, f B / (number of disparities - 1), m; focal_baseline =
  /// f B, px m, for the depth error of a disparity error (0: no motion test, see update).
  ObstacleTracker(const core::SignalParams& p, double z_contact_m, double z_near_limit_m = 0.0,
                  double focal_baseline = 0.0);

  /// Matches `obstacles` (this frame's, at time_s) to the tracks of the previous frame: a pair
  /// matches when their boxes' intersection covers at least track_min_overlap of the smaller box,
  /// best pairs first; unmatched obstacles start tracks, unmatched tracks end. Sets track_id; for a
  /// track with ttc_fit_min_frames samples within ttc_fit_window_s spanning at least
  /// ttc_fit_min_span_s, distance_m = the fitted
  /// distance now, closing_speed_mps = -slope, and ttc_s = (distance - z_contact) / closing speed
  /// (0 when already inside the contact depth; empty when closing slower than 1 cm/s).
  /// With p.coast_near_range, a track whose fit predicts it nearer than kNearRangeMargin times
  /// the near limit now is out of the matcher's reach: a matched obstacle takes the predicted
  /// distance and TTC (predicted = true, its measured distance is not added to the fit; so does
  /// one measured nearer than that, a saturated disparity, when its track closes in), and an
  /// unmatched track closing faster than 1 cm/s is appended to `obstacles` as a predicted one at
  /// its last box until its predicted TTC reaches 0.
  /// seen_frames counts the consecutive frames of the track, restarting at 1 when the blob's
  /// distance does not hold together with its motion: given a velocity, its distance must lie
  /// within kMotionTolerance of the last measured one moved by V_z over the time between them.
  void update(double time_s, std::vector<core::Obstacle>& obstacles);

  /// Whether a blob measured at z_now m agrees with the last measurement z_last of its track,
  /// dt s ago, and its velocity's V_z (m/s): |z_now - (z_last + V_z dt)| <= 0.1 z_now (the blob's
  /// extent changes from frame to frame) + 0.25 |V_z dt| (the velocity's own error) + twice the
  /// depth error of a 1 px disparity error in each reading, z^2 / (f B) (mismatches aside, the
  /// matcher errs by less). A mismatch read at a fixed wrong disparity while the flow says it moves
  /// fast fails it; so does one whose distance jumps between fragments.
  bool holds_together(double z_last, double z_now, double v_z, double dt) const;

  /// A blob fades some frames before its disparity leaves the matcher's range (the block's
  /// window straddles the limit, uniqueness fails): the near zone starts this far out.
  static constexpr double kNearRangeMargin = 1.25;

 private:
  struct Track {
    int id = 0;
    double first_s = 0.0;  ///< when the track started, s
    cv::Rect bbox;
    std::deque<double> t, z;  ///< samples of the measured (median) distance
    int seen = 0;             ///< consecutive frames seen, with a distance that holds together
    double last_t = 0.0, last_z = 0.0;  ///< the last measured distance (last_z 0: none)
    bool fitted = false;      ///< the last fit: z(t) = fit_z + fit_rate (t - fit_t)
    double fit_t = 0.0, fit_z = 0.0, fit_rate = 0.0;
    /// Predicted distance at time_s; false without a fit.
    bool predict(double time_s, double& z_now) const {
      z_now = fit_z + fit_rate * (time_s - fit_t);
      return fitted;
    }
  };
  /// True when `track` is predicted nearer than the matcher measures at time_s (coasting).
  bool out_of_reach(const Track& track, double time_s) const;
  /// Sets o's distance, closing speed and TTC from distance z_now and rate (m/s, < 0 closing).
  void set_from_fit(double z_now, double rate, core::Obstacle& o) const;

  core::SignalParams p_;
  double z_contact_m_;
  double z_near_limit_m_;
  double focal_baseline_;
  std::vector<Track> tracks_;
  int next_id_ = 1;
};

/// Severity with hysteresis: a higher severity is taken at once, a lower one only after it was
/// asked for severity_off_frames frames in a row; no signal means none at once (the region
/// signals have their own hysteresis).
class SeverityHold {
 public:
  explicit SeverityHold(const core::SignalParams& p) : off_frames_(p.severity_off_frames) {}
  core::Severity update(bool signal, core::Severity wanted);

 private:
  int off_frames_;
  core::Severity current_ = core::Severity::kNone;
  int lower_run_ = 0;
};

}  // namespace sg::vision
