#include <gtest/gtest.h>

#include "sg/core/error.hpp"

#include <cmath>

#include "sg/vision/signals.hpp"

namespace sg::vision {
namespace {

core::Camera camera_fb50() {
  core::Camera c;
  c.focal_px = 100.0;
  c.baseline_m = 0.5;  // depth = 50 / d
  return c;
}

struct Inputs {
  cv::Mat mask, disp, ttc;
};

Inputs blank(cv::Size size) {
  return {cv::Mat::zeros(size, CV_8U), cv::Mat(size, CV_32F, cv::Scalar(-1.0f)),
          cv::Mat(size, CV_32F, cv::Scalar(std::nanf("")))};
}

TEST(ExtractObstacles, RectangleGivesExactBoxAndCount) {
  Inputs in = blank({101, 77});
  in.mask(cv::Rect(13, 7, 21, 17)).setTo(255);
  in.disp(cv::Rect(13, 7, 21, 17)).setTo(10.0f);
  core::SignalParams p;
  p.min_area_px = 100;
  const auto obs = extract_obstacles(in.mask, in.disp, in.ttc, camera_fb50(), p);
  ASSERT_EQ(obs.size(), 1u);
  EXPECT_EQ(obs[0].bbox, cv::Rect(13, 7, 21, 17));
  EXPECT_EQ(obs[0].pixels, 21 * 17);
  EXPECT_DOUBLE_EQ(obs[0].distance_m, 5.0);
  EXPECT_FALSE(obs[0].ttc_s.has_value());
  EXPECT_EQ(cv::countNonZero(in.mask), 21 * 17);
}

TEST(ExtractObstacles, MeanVelocityOverFiniteValues) {
  Inputs in = blank({101, 77});
  const cv::Rect r(13, 7, 20, 10);
  in.mask(r).setTo(255);
  cv::Mat vel(in.mask.size(), CV_32FC3, cv::Scalar::all(std::nanf("")));
  // Left half (1, 0, -2), right half (3, 0, -4) except one column with a NaN in Y: skipped.
  vel(cv::Rect(13, 7, 10, 10)).setTo(cv::Scalar(1, 0, -2));
  vel(cv::Rect(23, 7, 9, 10)).setTo(cv::Scalar(3, 0, -4));
  vel(cv::Rect(32, 7, 1, 10)).setTo(cv::Scalar(100, std::nanf(""), 100));
  core::SignalParams p;
  p.min_area_px = 50;
  const auto obs = extract_obstacles(in.mask, in.disp, in.ttc, camera_fb50(), p, vel);
  ASSERT_EQ(obs.size(), 1u);
  ASSERT_TRUE(obs[0].velocity.has_value());
  const cv::Vec3d expected = (cv::Vec3d(1, 0, -2) * 100 + cv::Vec3d(3, 0, -4) * 90) / 190.0;
  for (int i = 0; i < 3; ++i) EXPECT_NEAR((*obs[0].velocity)[i], expected[i], 1e-9);
  // No finite value in the blob, or no map: no velocity.
  Inputs again = blank({101, 77});
  again.mask(r).setTo(255);
  cv::Mat unknown(again.mask.size(), CV_32FC3, cv::Scalar::all(std::nanf("")));
  EXPECT_FALSE(
      extract_obstacles(again.mask, again.disp, again.ttc, camera_fb50(), p, unknown)[0].velocity);
  EXPECT_FALSE(extract_obstacles(again.mask, again.disp, again.ttc, camera_fb50(), p)[0].velocity);
  EXPECT_THROW(extract_obstacles(again.mask, again.disp, again.ttc, camera_fb50(), p,
                                 cv::Mat(again.mask.size(), CV_32FC2)),
               core::InputError);
}

TEST(ExtractObstacles, SmallBlobsAreErasedFromTheMask) {
  Inputs in = blank({101, 77});
  in.mask(cv::Rect(5, 5, 10, 10)).setTo(255);    // 100 px: dropped
  in.mask(cv::Rect(50, 30, 20, 15)).setTo(255);  // 300 px: kept
  core::SignalParams p;
  p.open_size = 1;
  p.min_area_px = 150;
  const auto obs = extract_obstacles(in.mask, in.disp, in.ttc, camera_fb50(), p);
  ASSERT_EQ(obs.size(), 1u);
  EXPECT_EQ(obs[0].bbox, cv::Rect(50, 30, 20, 15));
  EXPECT_EQ(in.mask.at<uchar>(7, 7), 0);
  EXPECT_EQ(cv::countNonZero(in.mask), 300);
  EXPECT_EQ(obs[0].distance_m, 0.0);  // no valid disparity in the blob
}

TEST(ExtractObstacles, OpeningRemovesThinLinesAndJoinsNothing) {
  Inputs in = blank({101, 77});
  in.mask(cv::Rect(10, 10, 30, 30)).setTo(255);
  in.mask(cv::Rect(40, 20, 50, 1)).setTo(255);  // a 1-px line touching the square
  core::SignalParams p;
  p.open_size = 3;
  p.min_area_px = 10;
  const auto obs = extract_obstacles(in.mask, in.disp, in.ttc, camera_fb50(), p);
  ASSERT_EQ(obs.size(), 1u);
  EXPECT_EQ(obs[0].bbox, cv::Rect(10, 10, 30, 30));
  EXPECT_EQ(in.mask.at<uchar>(20, 60), 0);
  // Without the opening the line stays and widens the box.
  Inputs raw = blank({101, 77});
  raw.mask(cv::Rect(10, 10, 30, 30)).setTo(255);
  raw.mask(cv::Rect(40, 20, 50, 1)).setTo(255);
  p.open_size = 1;
  const auto obs_raw = extract_obstacles(raw.mask, raw.disp, raw.ttc, camera_fb50(), p);
  ASSERT_EQ(obs_raw.size(), 1u);
  EXPECT_EQ(obs_raw[0].bbox, cv::Rect(10, 10, 80, 30));
}

TEST(ExtractObstacles, MediansIgnoreInvalidDisparityAndMissingTtc) {
  Inputs in = blank({61, 41});
  const cv::Rect r(10, 10, 20, 15);  // rows 10..24
  in.mask(r).setTo(255);
  in.disp(cv::Rect(10, 10, 20, 5)).setTo(-1.0f);   // rows 10..14: 100 invalid
  in.disp(cv::Rect(10, 15, 20, 5)).setTo(10.0f);   // rows 15..19: 100 at 5 m
  in.disp(cv::Rect(10, 20, 20, 5)).setTo(20.0f);   // rows 20..24: 100 at 2.5 m ...
  in.disp.at<float>(24, 29) = 25.0f;                // ... one of them at 2 m
  in.disp.at<float>(23, 29) = -1.0f;                // ... one invalid
  // 199 valid depths sorted: 2, 2.5 x 98, 5 x 100 -> the middle one (index 99) is 5 m. Counting
  // the invalid pixels in would move it to 2.5 m.
  // TTC: finite values 9, 1, 2 and NaN elsewhere -> 2 s.
  in.ttc.at<float>(12, 12) = 9.0f;
  in.ttc.at<float>(13, 12) = 1.0f;
  in.ttc.at<float>(14, 12) = 2.0f;
  core::SignalParams p;
  p.open_size = 1;
  auto obs = extract_obstacles(in.mask, in.disp, in.ttc, camera_fb50(), p);
  ASSERT_EQ(obs.size(), 1u);
  EXPECT_DOUBLE_EQ(obs[0].distance_m, 5.0);
  ASSERT_TRUE(obs[0].ttc_s.has_value());
  EXPECT_DOUBLE_EQ(*obs[0].ttc_s, 2.0);
  // Even counts: the mean of the two middle values.
  in.ttc.at<float>(15, 12) = 4.0f;    // 1, 2, 4, 9 -> 3 s
  in.disp.at<float>(23, 29) = 20.0f;  // 2, 2.5 x 99, 5 x 100 -> (2.5 + 5) / 2
  obs = extract_obstacles(in.mask, in.disp, in.ttc, camera_fb50(), p);
  ASSERT_EQ(obs.size(), 1u);
  EXPECT_DOUBLE_EQ(*obs[0].ttc_s, 3.0);
  EXPECT_DOUBLE_EQ(obs[0].distance_m, 3.75);
}

TEST(ExtractObstacles, ObstaclesComeInRasterOrderOfFirstPixel) {
  Inputs in = blank({81, 61});
  in.mask(cv::Rect(0, 1, 12, 20)).setTo(255);   // A: first pixel (0, 1)
  in.mask(cv::Rect(40, 0, 12, 20)).setTo(255);  // B: first pixel (40, 0)
  in.mask(cv::Rect(20, 40, 12, 12)).setTo(255); // C
  core::SignalParams p;
  p.open_size = 1;
  p.min_area_px = 50;
  const auto obs = extract_obstacles(in.mask, in.disp, in.ttc, camera_fb50(), p);
  ASSERT_EQ(obs.size(), 3u);
  EXPECT_EQ(obs[0].bbox.x, 40);
  EXPECT_EQ(obs[1].bbox.x, 0);
  EXPECT_EQ(obs[2].bbox.x, 20);
}

TEST(ExtractObstacles, DiagonalNeighboursAreOneBlob) {
  Inputs in = blank({41, 41});
  for (int i = 0; i < 30; ++i) in.mask.at<uchar>(5 + i, 5 + i) = 255;
  core::SignalParams p;
  p.open_size = 1;
  p.min_area_px = 30;
  const auto obs = extract_obstacles(in.mask, in.disp, in.ttc, camera_fb50(), p);
  ASSERT_EQ(obs.size(), 1u);
  EXPECT_EQ(obs[0].pixels, 30);
}

TEST(Regions, NamesAndCountsOnOddWidth) {
  EXPECT_EQ(region_names(3), (std::vector<std::string>{"left", "centre", "right"}));
  EXPECT_EQ(region_names(2), (std::vector<std::string>{"r0", "r1"}));
  cv::Mat mask = cv::Mat::zeros(9, 31, CV_8U);  // columns [0,10) [10,20) [20,31)
  for (int x : {0, 9, 10, 19, 20, 30}) mask.at<uchar>(4, x) = 255;
  mask.at<uchar>(8, 15) = 255;
  EXPECT_EQ(count_region_pixels(mask, 3), (std::vector<int>{2, 3, 2}));
  // Four columns: [0,7) [7,15) [15,23) [23,31)
  EXPECT_EQ(count_region_pixels(mask, 4), (std::vector<int>{1, 2, 3, 1}));
  EXPECT_EQ(count_region_pixels(mask, 1), (std::vector<int>{7}));
}

std::vector<bool> fired(const std::vector<core::RegionSignal>& r) {
  std::vector<bool> out;
  for (const auto& s : r) out.push_back(s.fired);
  return out;
}

TEST(RegionHysteresis, OneNoisyFrameDoesNotFire) {
  core::SignalParams p;
  p.region_min_px = 10;
  p.on_k = 2;
  p.on_n = 3;
  p.off_m = 3;
  RegionHysteresis h(p);
  EXPECT_EQ(fired(h.update({0, 50, 0})), (std::vector<bool>{false, false, false}));
  EXPECT_EQ(fired(h.update({0, 0, 0})), (std::vector<bool>{false, false, false}));
  EXPECT_EQ(fired(h.update({0, 0, 0})), (std::vector<bool>{false, false, false}));
  EXPECT_EQ(fired(h.update({0, 50, 0})), (std::vector<bool>{false, false, false}));
  EXPECT_EQ(fired(h.update({0, 10, 0})), (std::vector<bool>{false, false, false}));  // not > 10
  EXPECT_EQ(fired(h.update({0, 0, 0})), (std::vector<bool>{false, false, false}));
}

TEST(RegionHysteresis, OnAfterKOfNOffAfterM) {
  core::SignalParams p;
  p.region_min_px = 10;
  p.on_k = 2;
  p.on_n = 3;
  p.off_m = 3;
  RegionHysteresis h(p);
  const std::vector<std::pair<int, bool>> seq = {
      {50, false}, {0, false}, {50, true},  // 2 of the last 3
      {0, true},                            // one clear frame does not silence
      {50, true}, {0, true}, {0, true},     // two clear frames: still on
      {0, false},                           // third clear frame: off
      {50, false},                          // history was forgotten: needs 2 of 3 again
      {50, true}};
  for (size_t i = 0; i < seq.size(); ++i) {
    const auto out = h.update({0, seq[i].first});
    ASSERT_EQ(out.size(), 2u);
    EXPECT_EQ(out[1].fired, seq[i].second) << "frame " << i;
    EXPECT_EQ(out[1].dangerous_px, seq[i].first);
    EXPECT_EQ(out[1].name, "r1");
    EXPECT_FALSE(out[0].fired);
  }
}

TEST(RegionHysteresis, ImmediateWithOneOfOne) {
  core::SignalParams p;
  p.region_min_px = 5;
  p.on_k = 1;
  p.on_n = 1;
  p.off_m = 1;
  RegionHysteresis h(p);
  EXPECT_TRUE(h.update({6})[0].fired);
  EXPECT_FALSE(h.update({5})[0].fired);
  EXPECT_TRUE(h.update({6})[0].fired);
}

core::Obstacle with_ttc(std::optional<double> t) {
  core::Obstacle o;
  o.ttc_s = t;
  return o;
}

TEST(Severity, Thresholds) {
  core::SignalParams p;
  p.ttc_danger_s = 1.5;
  p.ttc_warning_s = 3.0;
  using S = core::Severity;
  EXPECT_EQ(severity_of(true, {with_ttc(1.0)}, p), S::kDanger);
  EXPECT_EQ(severity_of(true, {with_ttc(1.5)}, p), S::kDanger);
  EXPECT_EQ(severity_of(true, {with_ttc(2.0)}, p), S::kWarning);
  EXPECT_EQ(severity_of(true, {with_ttc(3.0)}, p), S::kWarning);
  EXPECT_EQ(severity_of(true, {with_ttc(3.5)}, p), S::kNone);
  EXPECT_EQ(severity_of(true, {with_ttc(2.5), with_ttc(std::nullopt), with_ttc(1.2)}, p),
            S::kDanger);
  EXPECT_EQ(severity_of(false, {with_ttc(1.0)}, p), S::kNone);
  EXPECT_EQ(severity_of(true, {}, p), S::kWarning);
  EXPECT_EQ(severity_of(true, {with_ttc(std::nullopt)}, p), S::kWarning);
}

std::vector<core::RegionSignal> regions(std::vector<std::pair<bool, int>> v) {
  std::vector<core::RegionSignal> out;
  const auto names = region_names(static_cast<int>(v.size()));
  for (size_t i = 0; i < v.size(); ++i) out.push_back({names[i], v[i].first, v[i].second});
  return out;
}

TEST(Steering, ThreeColumns) {
  using St = core::Steering;
  EXPECT_EQ(steering_hint(regions({{false, 0}, {false, 0}, {false, 0}})), St::kStraight);
  EXPECT_EQ(steering_hint(regions({{true, 500}, {false, 0}, {false, 0}})), St::kStraight);
  EXPECT_EQ(steering_hint(regions({{false, 100}, {true, 900}, {false, 50}})), St::kRight);
  EXPECT_EQ(steering_hint(regions({{false, 50}, {true, 900}, {false, 100}})), St::kLeft);
  EXPECT_EQ(steering_hint(regions({{false, 70}, {true, 900}, {false, 70}})), St::kLeft);
  EXPECT_EQ(steering_hint(regions({{true, 10}, {true, 900}, {false, 500}})), St::kRight);
  EXPECT_EQ(steering_hint(regions({{false, 500}, {true, 900}, {true, 10}})), St::kLeft);
  EXPECT_EQ(steering_hint(regions({{true, 1}, {true, 1}, {true, 1}})), St::kStop);
}

TEST(Steering, OtherColumnCounts) {
  using St = core::Steering;
  EXPECT_EQ(steering_hint(regions({{true, 5}})), St::kStop);
  EXPECT_EQ(steering_hint(regions({{false, 5}})), St::kStraight);
  EXPECT_EQ(steering_hint(regions({{true, 5}, {false, 0}})), St::kRight);
  EXPECT_EQ(steering_hint(regions({{false, 0}, {false, 0}, {false, 0}, {false, 0}})),
            St::kStraight);
  // Four columns: the two middle ones are equally central; fewer pixels wins, then left.
  EXPECT_EQ(steering_hint(regions({{false, 0}, {false, 30}, {false, 20}, {true, 99}})),
            St::kRight);
  EXPECT_EQ(steering_hint(regions({{false, 0}, {true, 30}, {false, 20}, {false, 0}})),
            St::kRight);
  // Five columns: middle blocked, its neighbours too; the outer ones decide.
  EXPECT_EQ(steering_hint(regions({{false, 40}, {true, 1}, {true, 1}, {true, 1}, {false, 30}})),
            St::kRight);
  EXPECT_EQ(steering_hint(regions({{false, 0}, {true, 1}, {false, 0}, {true, 1}, {false, 0}})),
            St::kStraight);
  EXPECT_EQ(steering_hint(regions({{true, 1}, {true, 1}, {true, 1}, {true, 1}, {true, 1}})),
            St::kStop);
}

}  // namespace
}  // namespace sg::vision
