#pragma once
/// Detection accuracy against ground truth (docs/outputs.md, "Evaluation").
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "sg/core/detection.hpp"
#include "sg/core/ground_truth.hpp"

namespace sg::eval {

struct DetectionReport {
  int frames = 0;
  int gt_alarm_frames = 0;
  int alarm_frames = 0;        ///< frames whose signal fired
  int true_alarm_frames = 0;   ///< fired and GT alarm
  double precision = 0.0;      ///< true / alarm frames (1 when no alarm frames)
  double recall = 0.0;         ///< true / GT alarm frames (1 when no GT alarm frames)
  /// Recall without the first `settle_frames` frames of each run of GT alarm frames.
  double recall_settled = 0.0;
  /// Alarm frames among GT-clear frames / GT-clear frames (0 when there are none).
  double false_alarm_rate = 0.0;
  /// Per colliding obstacle id: its GT TTC at the first frame that is a GT alarm, where it is
  /// colliding, and the signal fired; nullopt when never.
  std::map<int, std::optional<double>> lead_times_s;
  /// Intersection over union of the detected and GT danger masks summed over all frames (1 when
  /// both are empty everywhere).
  double danger_iou = 0.0;
  std::optional<int> first_alarm_frame;
  /// TTC accuracy over GT alarm frames where a detected obstacle has a TTC: |TTC - GT| / GT of
  /// the detected obstacle covering most of the GT danger mask, against the colliding obstacle
  /// nearest to contact. Median and 90th percentile (nearest rank); empty when no such frame.
  int ttc_frames = 0;
  std::optional<double> ttc_rel_error_median, ttc_rel_error_p90;
  /// The largest of those errors after the first kTtcSettleFrames frames of each run of GT alarm
  /// frames (the track's fit needs some frames); empty when no such frame.
  std::optional<double> ttc_rel_error_max_settled;
  static constexpr int kTtcSettleFrames = 5;
  /// Frames whose severity differs from the previous frame's (none -> warning -> danger is 2).
  int severity_changes = 0;

  nlohmann::json to_json() const;
  /// A human-readable table, one metric per line.
  std::string table() const;
};

/// Streams (detection, truth) pairs in frame order.
class DetectionEvaluator {
 public:
  explicit DetectionEvaluator(int settle_frames = 3) : settle_frames_(settle_frames) {}
  /// gt_danger may be empty (then the frame does not count towards danger_iou).
  void add(const core::Detection& detection, const core::FrameTruth& truth,
           const cv::Mat& gt_danger);
  DetectionReport report() const;

 private:
  int settle_frames_;
  int frames_ = 0, gt_alarm_ = 0, alarm_ = 0, true_alarm_ = 0, false_alarm_ = 0;
  int settled_gt_ = 0, settled_hit_ = 0, run_length_ = 0;
  long long inter_ = 0, uni_ = 0;
  std::optional<int> first_alarm_;
  std::map<int, std::optional<double>> lead_;
  std::vector<double> ttc_errors_;
  std::optional<double> ttc_error_max_settled_;
  core::Severity last_severity_ = core::Severity::kNone;
  int severity_changes_ = 0;
};

}  // namespace sg::eval
