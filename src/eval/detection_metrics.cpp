#include "sg/eval/detection_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace sg::eval {
namespace {

double ratio(int num, int den, double if_empty) {
  return den == 0 ? if_empty : static_cast<double>(num) / den;
}

}  // namespace

void DetectionEvaluator::add(const core::Detection& detection, const core::FrameTruth& truth,
                             const cv::Mat& gt_danger) {
  ++frames_;
  const bool fired = detection.signal;
  if (fired) {
    ++alarm_;
    if (!first_alarm_) first_alarm_ = detection.frame;
  }
  if (truth.alarm) {
    ++gt_alarm_;
    ++run_length_;
    if (fired) ++true_alarm_;
    if (run_length_ > settle_frames_) {
      ++settled_gt_;
      if (fired) ++settled_hit_;
    }
  } else {
    run_length_ = 0;
    if (fired) ++false_alarm_;
  }
  for (const auto& o : truth.obstacles) {
    if (!o.colliding) continue;
    auto [it, inserted] = lead_.try_emplace(o.id, std::nullopt);
    if (!it->second && truth.alarm && fired) it->second = o.ttc_s.value_or(0.0);
  }
  // TTC accuracy: the colliding obstacle nearest to contact against the detected obstacle that
  // covers most of the GT danger mask (the one with the smallest TTC without a mask).
  const core::ObstacleTruth* gt = nullptr;
  for (const auto& o : truth.obstacles)
    if (o.colliding && o.ttc_s && *o.ttc_s > 0 && (!gt || *o.ttc_s < *gt->ttc_s)) gt = &o;
  if (truth.alarm && gt) {
    const core::Obstacle* best = nullptr;
    double best_score = -1;
    for (const auto& o : detection.obstacles) {
      if (!o.ttc_s) continue;
      const double score = gt_danger.empty()
                               ? -*o.ttc_s
                               : cv::countNonZero(gt_danger(
                                     o.bbox & cv::Rect(0, 0, gt_danger.cols, gt_danger.rows)));
      if (!best || score > best_score) best = &o, best_score = score;
    }
    if (best) {
      const double error = std::abs(*best->ttc_s - *gt->ttc_s) / *gt->ttc_s;
      ttc_errors_.push_back(error);
      if (run_length_ > DetectionReport::kTtcSettleFrames)
        ttc_error_max_settled_ = std::max(ttc_error_max_settled_.value_or(0.0), error);
    }
  }
  if (frames_ > 1 && detection.severity != last_severity_) ++severity_changes_;
  last_severity_ = detection.severity;
  if (!gt_danger.empty() && !detection.danger.empty()) {
    CV_Assert(gt_danger.size() == detection.danger.size());
    cv::Mat gt = gt_danger > 0, det = detection.danger > 0;
    inter_ += cv::countNonZero(gt & det);
    uni_ += cv::countNonZero(gt | det);
  }
}

DetectionReport DetectionEvaluator::report() const {
  DetectionReport r;
  r.frames = frames_;
  r.gt_alarm_frames = gt_alarm_;
  r.alarm_frames = alarm_;
  r.true_alarm_frames = true_alarm_;
  r.precision = ratio(true_alarm_, alarm_, 1.0);
  r.recall = ratio(true_alarm_, gt_alarm_, 1.0);
  r.recall_settled = ratio(settled_hit_, settled_gt_, r.recall);
  r.false_alarm_rate = ratio(false_alarm_, frames_ - gt_alarm_, 0.0);
  r.lead_times_s = lead_;
  r.danger_iou = uni_ == 0 ? 1.0 : static_cast<double>(inter_) / static_cast<double>(uni_);
  r.first_alarm_frame = first_alarm_;
  r.ttc_frames = static_cast<int>(ttc_errors_.size());
  if (!ttc_errors_.empty()) {
    std::vector<double> e = ttc_errors_;
    std::sort(e.begin(), e.end());
    auto at = [&e](double q) {  // nearest rank
      const size_t i = static_cast<size_t>(std::ceil(q * e.size())) - 1;
      return e[std::min(i, e.size() - 1)];
    };
    r.ttc_rel_error_median = at(0.5);
    r.ttc_rel_error_p90 = at(0.9);
  }
  r.ttc_rel_error_max_settled = ttc_error_max_settled_;
  r.severity_changes = severity_changes_;
  return r;
}

nlohmann::json DetectionReport::to_json() const {
  auto opt = [](const std::optional<double>& v) {
    return v ? nlohmann::json(*v) : nlohmann::json();
  };
  nlohmann::json lead = nlohmann::json::array();
  for (const auto& [id, t] : lead_times_s) {
    lead.push_back({{"id", id}, {"lead_time_s", t ? nlohmann::json(*t) : nlohmann::json()}});
  }
  return {{"frames", frames},
          {"gt_alarm_frames", gt_alarm_frames},
          {"alarm_frames", alarm_frames},
          {"true_alarm_frames", true_alarm_frames},
          {"precision", precision},
          {"recall", recall},
          {"recall_settled", recall_settled},
          {"false_alarm_rate", false_alarm_rate},
          {"lead_times_s", lead},
          {"danger_iou", danger_iou},
          {"ttc_frames", ttc_frames},
          {"ttc_rel_error_median", opt(ttc_rel_error_median)},
          {"ttc_rel_error_p90", opt(ttc_rel_error_p90)},
          {"ttc_rel_error_max_settled", opt(ttc_rel_error_max_settled)},
          {"severity_changes", severity_changes},
          {"first_alarm_frame",
           first_alarm_frame ? nlohmann::json(*first_alarm_frame) : nlohmann::json()}};
}

std::string DetectionReport::table() const {
  std::ostringstream s;
  s << std::fixed << std::setprecision(3);
  s << "  frames            " << frames << "\n"
    << "  gt alarm frames   " << gt_alarm_frames << "\n"
    << "  alarm frames      " << alarm_frames << " (" << true_alarm_frames << " true)\n"
    << "  precision         " << precision << "\n"
    << "  recall            " << recall << "\n"
    << "  recall settled    " << recall_settled << "\n"
    << "  false alarm rate  " << false_alarm_rate << "\n"
    << "  danger IoU        " << danger_iou << "\n";
  if (ttc_rel_error_median) {
    s << "  TTC rel. error    median " << *ttc_rel_error_median << "  p90 " << *ttc_rel_error_p90
      << " (" << ttc_frames << " frames)";
    if (ttc_rel_error_max_settled)
      s << "  max after " << kTtcSettleFrames << " frames " << *ttc_rel_error_max_settled;
    s << "\n";
  }
  s << "  severity changes  " << severity_changes << "\n";
  s << std::setprecision(2);
  for (const auto& [id, t] : lead_times_s) {
    s << "  lead time id " << id << "    ";
    if (t) s << *t << " s\n";
    else s << "never alarmed\n";
  }
  return s.str();
}

}  // namespace sg::eval
