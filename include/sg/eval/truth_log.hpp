#pragma once
/// Real recordings scored against a truth log (DESIGN 4.1, docs/real-recordings.md): the log's
/// reader, the quantities derived from it (closing speed, truth TTC, due and quiet frames) and the
/// scorer of a run's detections. Pure functions and one streaming scorer; no threads.
///
/// The log is a CSV file with a header row. Columns are found by name, others are ignored:
///  * `frame` (integer >= 0) and/or `t_s` (seconds since the first frame): at least one; each
///    strictly increasing down the file;
///  * the distance to the obstacle of interest, m: `distance_m`, else `board_distance_m`, or the
///    column TruthLogOptions::distance_column names; a blank cell = unknown;
///  * `phase`: a free word per row (approach, retreat, still...), compared in lower case.
/// A log needs a distance or a phase column. Blank lines and lines starting with '#' are skipped.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "sg/core/detection.hpp"

namespace sg::eval {

struct TruthLogOptions {
  /// The distance column's name; empty = `distance_m`, or `board_distance_m` when the log has no
  /// `distance_m`.
  std::string distance_column;
};

/// One data row of a truth log.
struct TruthRow {
  int line = 0;                      ///< 1-based line of the file
  std::optional<int> frame;          ///< when the log has a `frame` column
  std::optional<double> t_s;         ///< when the log has a `t_s` column, s
  std::optional<double> distance_m;  ///< finite, >= 0; empty = unknown (blank cell)
  std::string phase;                 ///< lower case; empty when no phase column or blank
};

struct TruthLog {
  std::string name;  ///< file name for messages
  bool has_frame = false, has_time = false, has_phase = false;
  std::string distance_column;  ///< empty = the log has no distance column
  std::vector<TruthRow> rows;   ///< at least one
};

/// Parses the text of a truth log. `name` names the file in messages. Throws core::InputError
/// "<name> line L, column C (<column>): <problem>" (or "<name>: <problem>" for the file as a whole)
/// for: an empty text, a header of numbers, no frame/t_s column, a named distance column that is
/// missing, neither distance nor phase column, a repeated column name, a row with more or fewer
/// cells than the header, a blank or non-numeric frame or t_s, a frame or t_s that does not
/// increase, a negative frame, a non-numeric, non-finite or negative distance, no data row.
TruthLog parse_truth_log(const std::string& text, const std::string& name,
                         const TruthLogOptions& options = {});

/// Reads and parses the file (core::InputError also when it is missing or unreadable).
TruthLog read_truth_log(const std::filesystem::path& path, const TruthLogOptions& options = {});

/// The phases that count as quiet by default: still, creep, retreat, quiet, static, stop.
std::vector<std::string> default_quiet_phases();

/// How the truth is turned into frame classes (docs/real-recordings.md).
struct TruthCriteria {
  double z_contact_m = 0.5;  ///< the platform's contact plane (Envelope::z_contact_m), m
  double horizon_s = 3.0;    ///< due when the truth TTC is within this (Envelope::horizon_s), s
  double fit_half_window_s = 0.5;  ///< closing speed: centred fit over t +- this, s
  int fit_min_points = 3;          ///< known distances the fit needs in its window
  double min_closing_mps = 0.05;   ///< slower than this is not an approach, m/s
  /// Phases whose frames are quiet (lower case). Without a phase column, quiet = closing speed
  /// known and <= min_closing_mps.
  std::vector<std::string> quiet_phases = default_quiet_phases();
  /// The quiet phase whose alarms count as "still" alarms (the camera stands still). Without a
  /// phase column, still = quiet and |closing speed| < min_closing_mps.
  std::string still_phase = "still";
  /// When set, due = not quiet and distance known and <= this, m (instead of the TTC rule).
  std::optional<double> due_within_m;
  /// Contact scores: recall over [t_contact - this, t_contact], s.
  double last_window_s = 2.5;
  /// Lead: the first alarm counts only if it is within horizon_s + this before contact, s.
  double lead_slack_s = 2.0;
};

/// Parses "a,b,c" into lower-case phase names (spaces trimmed, empty entries dropped).
std::vector<std::string> parse_phase_list(const std::string& text);

/// A log row with what is derived from it.
struct TruthFrame {
  std::optional<int> frame;  ///< the row's frame, when the log has that column
  double t_s = 0.0;          ///< t_s, or frame * frame_period_s without that column
  std::optional<double> distance_m;
  std::string phase;
  /// -slope of a least-squares line through the known distances with |t' - t| <= half window, m/s
  /// (> 0 = approaching); empty when fewer than fit_min_points of them.
  std::optional<double> closing_mps;
  /// (distance - z_contact) / closing speed when the closing speed is > min_closing_mps and the
  /// distance > z_contact; 0 when the distance is <= z_contact during such an approach; else empty.
  std::optional<double> ttc_s;
  bool quiet = false;  ///< standing still or moving away (phase, or closing speed)
  bool still = false;  ///< quiet because the camera stands still
  bool due = false;    ///< an alarm is expected (see TruthCriteria::due_within_m)
};

/// Least-squares slope of y over t, or empty when fewer than two points or all t equal.
std::optional<double> fit_slope(const std::vector<double>& t, const std::vector<double>& y);

/// Derives every row. `frame_period_s` (> 0) gives the rows' times when the log has no t_s
/// column (the input's frame period).
std::vector<TruthFrame> derive_truth(const TruthLog& log, const TruthCriteria& criteria,
                                     double frame_period_s);

/// The scores of one contact event: the truth distance crossing from above z_contact to at or
/// under it (the first frame at or under).
struct ContactScore {
  int frame = 0;
  double t_s = 0.0;
  /// t_contact - t of the earliest alarm frame after the last quiet frame before the contact and
  /// within horizon + lead_slack_s before it; empty when there is none.
  std::optional<double> lead_s;
  int last_frames = 0;        ///< scored frames with t in [t_contact - last_window_s, t_contact]
  int last_alarm_frames = 0;  ///< those that alarm
  /// last_alarm_frames / last_frames (empty when no frame).
  std::optional<double> recall_last() const;
};

/// A run's detections against a truth log.
struct TruthReport {
  int frames = 0;                ///< detections
  int scored_frames = 0;         ///< with a matching truth row
  int unscored_frames = 0;       ///< without one (past the end of the log, or a gap in it)
  int rows_past_last_frame = 0;  ///< log rows after the last frame (a warning, not an error)
  bool matched_by_frame = true;  ///< rows matched by `frame`, else by nearest t_s
  int alarm_frames = 0;          ///< all frames whose signal fired
  int due_frames = 0, due_alarm_frames = 0;
  int quiet_frames = 0, quiet_alarm_frames = 0;
  int still_frames = 0, still_alarm_frames = 0;
  std::vector<ContactScore> contacts;
  double last_window_s = 2.5;  ///< the window of ContactScore::last_frames (criteria), s
  /// Median over alarm frames with a known truth distance and an obstacle of
  /// |nearest obstacle distance - truth| / truth, and how many frames it is over.
  int distance_frames = 0;
  std::optional<double> distance_rel_error_median;

  /// due_alarm_frames / due_frames; empty when no due frame.
  std::optional<double> recall() const;
  /// quiet_alarm_frames / quiet_frames; empty when no quiet frame.
  std::optional<double> false_alarm_rate() const;

  nlohmann::json to_json() const;
  /// A human-readable table, one metric per line.
  std::string table() const;
};

/// Streams detections in frame order and scores them against the derived truth. Rows are matched
/// to a detection by its frame index when the log has a `frame` column, else by the nearest t_s
/// (within half the log's median row interval; outside, the frame is unscored).
class TruthScorer {
 public:
  TruthScorer(std::vector<TruthFrame> truth, TruthCriteria criteria);
  void add(const core::Detection& detection);
  TruthReport report() const;

 private:
  /// What the scorer keeps of a detection.
  struct Scored {
    int frame = 0;
    int row = -1;  ///< index into truth_, -1 = unscored
    bool alarm = false;
    std::optional<double> nearest_m;
  };
  int match(const core::Detection& detection) const;

  std::vector<TruthFrame> truth_;
  TruthCriteria criteria_;
  bool by_frame_ = true;
  double match_tolerance_s_ = 0.0;
  std::vector<Scored> scored_;
};

}  // namespace sg::eval
