// The central-median baseline over synthetic sequences: a textured plane approaching, standing
// and receding at known disparities, and the loop over a source.
#include <gtest/gtest.h>

#include <vector>

#include "../vision/synthetic.hpp"
#include "sg/core/error.hpp"
#include "sg/io/memory_source.hpp"
#include "sg/pipeline/central_baseline.hpp"

namespace sg::pipeline {
namespace {

core::Camera small_camera() {
  core::Camera c;
  c.width = 241;
  c.height = 161;
  c.focal_px = 250.0;
  c.baseline_m = 0.2;  // f*B = 50: disparity 10 = 5 m, 25 = 2 m
  c.cx = 120.0;
  c.cy = 80.0;
  c.fps = 10.0;
  return c;
}

/// Frames of a fronto-parallel textured plane at the given disparities, 10 fps.
std::vector<core::StereoFrame> plane_frames(const std::vector<float>& disparities) {
  std::vector<core::StereoFrame> frames;
  for (std::size_t i = 0; i < disparities.size(); ++i) {
    const vision::test::StereoPair pair =
        vision::test::shifted_pair({241, 161}, disparities[i], 11);
    core::StereoFrame f;
    f.index = static_cast<int>(i);
    f.time_s = static_cast<double>(i) / 10.0;
    f.left = pair.left;
    f.right = pair.right;
    frames.push_back(f);
  }
  return frames;
}


CentralBaselineOptions options() {
  CentralBaselineOptions o;
  o.params.bm.num_disparities = 48;
  o.params.bm.block_size = 9;
  return o;
}

TEST(CentralBaseline, ApproachingPlaneAlarmsOnceTheFitHasThreeFrames) {
  // 5.0, 4.55, 4.17, 3.85, 3.57, 3.33 m: about 3-4 m/s, TTC about 1 s.
  const std::vector<float> d = {10, 11, 12, 13, 14, 15};
  CentralBaseline baseline(options(), small_camera());
  for (const core::StereoFrame& f : plane_frames(d)) {
    const core::Detection det = baseline.process(f);
    EXPECT_EQ(det.frame, f.index);
    EXPECT_DOUBLE_EQ(det.time_s, f.time_s);
    ASSERT_EQ(det.obstacles.size(), 1u);
    const core::Obstacle& o = det.obstacles[0];
    EXPECT_EQ(o.bbox, cv::Rect(60, 40, 120, 80));
    const double truth = 50.0 / d[static_cast<std::size_t>(f.index)];
    EXPECT_NEAR(o.distance_m, truth, 0.02 * truth) << f.index;
    ASSERT_EQ(det.regions.size(), 1u);
    EXPECT_EQ(det.regions[0].fired, det.signal);
    if (f.index < 2) {
      EXPECT_FALSE(det.signal) << f.index;  // fewer than 3 distances in the last 0.5 s
      EXPECT_FALSE(o.ttc_s);
      continue;
    }
    EXPECT_TRUE(det.signal) << f.index;
    ASSERT_TRUE(o.closing_speed_mps);
    EXPECT_GT(*o.closing_speed_mps, 2.5);
    EXPECT_LT(*o.closing_speed_mps, 5.0);
    ASSERT_TRUE(o.ttc_s);
    EXPECT_NEAR(*o.ttc_s, (o.distance_m - 0.5) / *o.closing_speed_mps, 1e-9);
    EXPECT_EQ(det.severity, *o.ttc_s <= 1.5 ? core::Severity::kDanger : core::Severity::kWarning);
  }
}

TEST(CentralBaseline, StandingAndRecedingPlanesNeverAlarm) {
  for (const std::vector<float>& d :
       {std::vector<float>{20, 20, 20, 20, 20, 20}, std::vector<float>{20, 19, 18, 17, 16, 15}}) {
    CentralBaseline baseline(options(), small_camera());
    for (const core::StereoFrame& f : plane_frames(d)) {
      const core::Detection det = baseline.process(f);
      EXPECT_FALSE(det.signal) << f.index;
      EXPECT_EQ(det.severity, core::Severity::kNone);
    }
  }
}

TEST(CentralBaseline, InsideTheContactPlaneAlarmsAtOnce) {
  // 45 px = 1.11 m: move the contact plane beyond it.
  CentralBaselineOptions o = options();
  o.params.envelope.z_contact_m = 1.5;
  CentralBaseline baseline(o, small_camera());
  const core::Detection det = baseline.process(plane_frames({45})[0]);
  EXPECT_TRUE(det.signal);
  EXPECT_EQ(det.severity, core::Severity::kDanger);
}

TEST(CentralBaseline, TheWindowIsTrailingHalfASecond) {
  // Far and standing for 1 s, then one jump nearer: the fit at the jump uses frames 5..10 only
  // (t >= 0.5), so it sees a closing speed.
  std::vector<float> d(11, 10.0f);
  d[10] = 14.0f;
  CentralBaseline baseline(options(), small_camera());
  core::Detection last;
  for (const core::StereoFrame& f : plane_frames(d)) last = baseline.process(f);
  ASSERT_TRUE(last.obstacles[0].closing_speed_mps);
  // Least squares over t = 0.5 .. 1.0 (6 frames) with only the last point at 3.57 m instead of
  // 5 m: 1.43 * 0.25 / 0.175 = 2.04 m/s (7 frames would give 1.53, all 11 0.65).
  EXPECT_NEAR(*last.obstacles[0].closing_speed_mps, 2.04, 0.25);
}

TEST(CentralBaseline, RunsASourceAndCountsAlarms) {
  const std::vector<core::StereoFrame> pairs = plane_frames({10, 11, 12, 13, 14, 15});
  io::MemorySource source(pairs, small_camera());
  std::vector<int> frames;
  const RunSummary s = run_central_baseline(
      source, options(), [&](const core::StereoFrame& f, const core::Detection& d) {
        EXPECT_EQ(f.index, d.frame);
        frames.push_back(d.frame);
      });
  EXPECT_EQ(frames, (std::vector<int>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(s.frames, 6);
  EXPECT_EQ(s.alarm_frames, 4);
  EXPECT_EQ(s.first_alarm_frame, 2);
  EXPECT_EQ(s.mode, "central-median");
}

TEST(CentralBaseline, InvalidParametersAreAnInputError) {
  const std::vector<core::StereoFrame> pairs = plane_frames({10});
  io::MemorySource source(pairs, small_camera());
  CentralBaselineOptions o = options();
  o.params.bm.num_disparities = 40;  // not a multiple of 16
  EXPECT_THROW(run_central_baseline(source, o, {}), core::InputError);
}

}  // namespace
}  // namespace sg::pipeline
