#include <gtest/gtest.h>

#include "sg/eval/detection_metrics.hpp"

namespace sg::eval {
namespace {

core::Detection detection(int frame, bool signal) {
  core::Detection d;
  d.frame = frame;
  d.signal = signal;
  return d;
}

core::FrameTruth truth(int frame, bool alarm, std::optional<double> ttc = std::nullopt) {
  core::FrameTruth t;
  t.frame = frame;
  t.alarm = alarm;
  if (ttc || alarm) t.obstacles.push_back({1, true, ttc, 500});
  return t;
}

TEST(DetectionMetrics, CountsRecallPrecisionAndFalseAlarms) {
  // GT: frames 0-3 clear, 4-11 alarm (8 frames). Detected: 2 (false), 6..11.
  DetectionEvaluator ev(3);
  for (int i = 0; i < 12; ++i) {
    const bool gt = i >= 4;
    const bool fired = i == 2 || i >= 6;
    ev.add(detection(i, fired), truth(i, gt, gt ? std::optional<double>(3.0 - 0.1 * i)
                                                : std::nullopt),
           cv::Mat());
  }
  const DetectionReport r = ev.report();
  EXPECT_EQ(r.frames, 12);
  EXPECT_EQ(r.gt_alarm_frames, 8);
  EXPECT_EQ(r.alarm_frames, 7);
  EXPECT_EQ(r.true_alarm_frames, 6);
  EXPECT_DOUBLE_EQ(r.precision, 6.0 / 7.0);
  EXPECT_DOUBLE_EQ(r.recall, 6.0 / 8.0);
  // Settled: GT frames 7..11 (the first 3 of the run, 4..6, are left out); hits 7..11.
  EXPECT_DOUBLE_EQ(r.recall_settled, 1.0);
  EXPECT_DOUBLE_EQ(r.false_alarm_rate, 1.0 / 4.0);
  ASSERT_EQ(r.lead_times_s.count(1), 1u);
  ASSERT_TRUE(r.lead_times_s.at(1).has_value());
  EXPECT_DOUBLE_EQ(*r.lead_times_s.at(1), 3.0 - 0.6);  // GT TTC at frame 6
  EXPECT_EQ(r.first_alarm_frame, 2);
}

TEST(DetectionMetrics, SettledRecallRestartsWithEachRun) {
  DetectionEvaluator ev(1);
  const bool gt[] = {true, true, false, true, true};
  const bool fired[] = {false, true, false, false, false};
  for (int i = 0; i < 5; ++i) ev.add(detection(i, fired[i]), truth(i, gt[i], 1.0), cv::Mat());
  const DetectionReport r = ev.report();
  // Settled GT frames: 1 and 4; only 1 was hit.
  EXPECT_DOUBLE_EQ(r.recall_settled, 0.5);
  EXPECT_DOUBLE_EQ(r.recall, 0.25);
}

TEST(DetectionMetrics, TtcErrorsMedianP90AndMaxAfterTheFirstFiveFramesOfARun) {
  // A 10-frame GT alarm run, GT TTC 2.0 s; the detected TTC is off by 50 % on frame 1 (inside
  // the first 5 frames), by 20 % on frame 7 and exact elsewhere; frame 3 has no TTC at all.
  DetectionEvaluator ev(3);
  for (int i = 0; i < 10; ++i) {
    core::Detection d = detection(i, true);
    d.severity = i < 6 ? core::Severity::kWarning : core::Severity::kDanger;
    if (i != 3) {
      core::Obstacle o;
      o.bbox = cv::Rect(0, 0, 4, 4);
      o.ttc_s = i == 1 ? 3.0 : i == 7 ? 1.6 : 2.0;
      d.obstacles.push_back(o);
    }
    ev.add(d, truth(i, true, 2.0), cv::Mat());
  }
  const DetectionReport r = ev.report();
  EXPECT_EQ(r.ttc_frames, 9);
  ASSERT_TRUE(r.ttc_rel_error_median && r.ttc_rel_error_p90 && r.ttc_rel_error_max_settled);
  EXPECT_DOUBLE_EQ(*r.ttc_rel_error_median, 0.0);
  EXPECT_NEAR(*r.ttc_rel_error_p90, 0.5, 1e-12);          // nearest rank 9 of the 9 errors
  EXPECT_NEAR(*r.ttc_rel_error_max_settled, 0.2, 1e-12);  // frame 1's 0.5 is not settled
  EXPECT_EQ(r.severity_changes, 1);                       // warning -> danger at frame 6
}

TEST(DetectionMetrics, NeverAlarmedObstacleHasNoLeadTime) {
  DetectionEvaluator ev;
  for (int i = 0; i < 5; ++i) ev.add(detection(i, false), truth(i, true, 2.0), cv::Mat());
  const DetectionReport r = ev.report();
  ASSERT_EQ(r.lead_times_s.size(), 1u);
  EXPECT_FALSE(r.lead_times_s.at(1).has_value());
  EXPECT_TRUE(r.to_json()["lead_times_s"][0]["lead_time_s"].is_null());
  EXPECT_NE(r.table().find("never alarmed"), std::string::npos);
}

TEST(DetectionMetrics, DangerIouOverAllFrames) {
  DetectionEvaluator ev;
  cv::Mat gt = cv::Mat::zeros(7, 9, CV_8U), det = cv::Mat::zeros(7, 9, CV_8U);
  gt(cv::Rect(0, 0, 4, 2)).setTo(255);   // 8 px
  det(cv::Rect(2, 0, 4, 2)).setTo(255);  // 8 px, 4 shared
  core::Detection d = detection(0, true);
  d.danger = det;
  ev.add(d, truth(0, true, 1.0), gt);
  EXPECT_DOUBLE_EQ(ev.report().danger_iou, 4.0 / 12.0);
}

TEST(DetectionMetrics, QuietSceneIsPerfect) {
  DetectionEvaluator ev;
  for (int i = 0; i < 4; ++i) ev.add(detection(i, false), truth(i, false), cv::Mat());
  const DetectionReport r = ev.report();
  EXPECT_DOUBLE_EQ(r.false_alarm_rate, 0.0);
  EXPECT_DOUBLE_EQ(r.precision, 1.0);
  EXPECT_DOUBLE_EQ(r.recall, 1.0);
  EXPECT_TRUE(r.lead_times_s.empty());
}

}  // namespace
}  // namespace sg::eval
