#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include "sg/core/error.hpp"
#include "sg/vision/detector.hpp"
#include "sg/vision/frame_kernels.hpp"
#include "sg/vision/stereo_bm.hpp"
#include "synthetic.hpp"

namespace sg::vision {
namespace {

using test::camera;

const cv::Rect kPatch(60, 45, 60, 31);  // centre columns [53,107) and 13 columns of the right

/// Background at 25 m (beyond z_max) with a patch at depth z, quantized to 1/16 px like BM, and
/// uniform noise of up to `noise` px on every valid pixel.
cv::Mat scene(double z, cv::RNG& rng, double noise = 0.0) {
  const core::Camera cam = camera();
  cv::Mat d(cam.height, cam.width, CV_32F, cv::Scalar(cam.disparity(25.0)));
  d(kPatch).setTo(cam.disparity(z));
  d(cv::Rect(0, 0, 20, 121)).setTo(-1.0f);  // BM's dead band on the left
  for (int y = 0; y < d.rows; ++y)
    for (int x = 0; x < d.cols; ++x) {
      float& v = d.at<float>(y, x);
      if (v < 0) continue;
      v = std::round((v + static_cast<float>(rng.uniform(-noise, noise))) * 16.0f) / 16.0f;
    }
  return d;
}

core::StereoFrame frame(int i) {
  core::StereoFrame f;
  f.index = i;
  f.time_s = i / camera().fps;
  return f;
}

TEST(Detector, ApproachingPatchFiresAfterHysteresisInItsRegions) {
  const core::DetectorParams params;  // defaults
  Detector det(params, camera());
  cv::RNG rng(5);
  std::vector<core::Detection> out;
  for (int i = 0; i < 24; ++i) {
    const double z = 8.0 - 0.25 * i;  // 2.5 m/s towards the camera
    out.push_back(det.process(frame(i), {scene(z, rng, 0.1), {}}));
  }
  EXPECT_EQ(out[0].frame, 0);
  EXPECT_EQ(out[5].frame, 5);
  EXPECT_DOUBLE_EQ(out[5].time_s, 0.5);
  EXPECT_EQ(cv::countNonZero(out[0].danger), 0);  // no history yet

  int first_dangerous = -1;
  for (int i = 0; i < 24 && first_dangerous < 0; ++i)
    if (out[i].regions.size() == 3 && out[i].regions[1].dangerous_px > params.signal.region_min_px)
      first_dangerous = i;
  // TTC = Z / v <= 3 s from Z = 7.5 m (frame 2), needing D_i - D_{i-k} >= 1 px: gap 5 first
  // reaches it at frame 5 (8 m -> 6.75 m: 1.16 px).
  ASSERT_GE(first_dangerous, 2);
  ASSERT_LE(first_dangerous, 6);
  const int first_signal = first_dangerous + params.signal.on_k - 1;
  for (int i = 0; i < first_signal; ++i) EXPECT_FALSE(out[i].signal) << "frame " << i;
  for (int i = first_signal; i < 24; ++i) {
    const core::Detection& d = out[i];
    EXPECT_TRUE(d.signal) << "frame " << i;
    ASSERT_EQ(d.regions.size(), 3u);
    EXPECT_FALSE(d.regions[0].fired);
    EXPECT_TRUE(d.regions[1].fired);
    EXPECT_TRUE(d.regions[2].fired);
    EXPECT_EQ(d.steering, core::Steering::kLeft) << "frame " << i;
    ASSERT_EQ(d.obstacles.size(), 1u) << "frame " << i;
    EXPECT_EQ(d.obstacles[0].bbox, kPatch);
    const double z = 8.0 - 0.25 * i;
    EXPECT_NEAR(d.obstacles[0].distance_m, z, 0.05 * z);
    ASSERT_TRUE(d.obstacles[0].ttc_s.has_value());
    EXPECT_NEAR(*d.obstacles[0].ttc_s, z / 2.5, 0.25 * z / 2.5) << "frame " << i;
    EXPECT_EQ(d.danger.type(), CV_8UC1);
  }
  EXPECT_EQ(out[first_signal].severity, core::Severity::kWarning);
  EXPECT_EQ(out[23].severity, core::Severity::kDanger);  // Z = 2.25 m, TTC 0.9 s
}

TEST(Detector, StaticAndRecedingScenesNeverFire) {
  const core::DetectorParams params;
  for (double speed : {0.0, -2.5}) {
    Detector det(params, camera());
    cv::RNG rng(6);
    for (int i = 0; i < 40; ++i) {
      const double z = 3.0 - speed * 0.1 * i;  // static at 3 m, or receding from 3 m
      const core::Detection d = det.process(frame(i), {scene(z, rng, 0.15), {}});
      EXPECT_FALSE(d.signal) << "speed " << speed << " frame " << i;
      EXPECT_EQ(cv::countNonZero(d.danger), 0) << "speed " << speed << " frame " << i;
      EXPECT_EQ(d.severity, core::Severity::kNone);
      EXPECT_EQ(d.steering, core::Steering::kStraight);
    }
  }
}

TEST(Detector, GapUsesTheFrameExactlyKFramesAgo) {
  core::DetectorParams params;
  params.stereo.gaps = {3};
  params.signal.on_k = 1;
  params.signal.on_n = 1;
  params.signal.confirm_frames = 1;
  Detector det(params, camera());
  const core::Camera cam = camera();
  std::vector<core::Detection> out;
  // Patch disparity 9, 10, 11, 12 px over frames 0..3 (Z 5.6 -> 4.2 m).
  for (int i = 0; i < 4; ++i) {
    cv::Mat d(cam.height, cam.width, CV_32F, cv::Scalar(-1.0f));
    d(kPatch).setTo(9.0f + i);
    out.push_back(det.process(frame(i), {d, {}}));
  }
  for (int i = 0; i < 3; ++i) EXPECT_FALSE(out[i].signal) << "frame " << i;  // no D_{i-3} yet
  ASSERT_TRUE(out[3].signal);
  ASSERT_EQ(out[3].obstacles.size(), 1u);
  // Against frame 0: 0.3 s * 9 / 3 = 0.9 s to the camera (frame 1 would give 1.5 s, frame 2
  // 3.3 s), scaled to the time to reach the contact depth: Z = 50 / 12 m, contact at 0.5 m.
  const double z = 50.0 / 12.0;
  EXPECT_NEAR(*out[3].obstacles[0].ttc_s, 0.9 * (z - 0.5) / z, 1e-6);
}

TEST(Detector, DroppedFramesStretchTheGapByTheirTime) {
  // A paced run that dropped frames 1 and 2: the detector sees frames 0 and 3. Gap 1 then spans
  // three frame periods, so the TTC must equal the one against frame 0 in the test above.
  core::DetectorParams params;
  params.stereo.gaps = {1};
  params.signal.on_k = 1;
  params.signal.on_n = 1;
  params.signal.confirm_frames = 1;
  Detector det(params, camera());
  const core::Camera cam = camera();
  core::Detection last;
  for (int i : {0, 3}) {
    cv::Mat d(cam.height, cam.width, CV_32F, cv::Scalar(-1.0f));
    d(kPatch).setTo(9.0f + i);
    last = det.process(frame(i), {d, {}});
  }
  ASSERT_TRUE(last.signal);
  ASSERT_EQ(last.obstacles.size(), 1u);
  const double z = 50.0 / 12.0;
  EXPECT_NEAR(*last.obstacles[0].ttc_s, 0.9 * (z - 0.5) / z, 1e-6);
  cv::Mat d(cam.height, cam.width, CV_32F, cv::Scalar(-1.0f));
  EXPECT_THROW(det.process(frame(3), {d, {}}), core::InputError);  // not increasing
}

// ---------------------------------------------------------------------------------------------
// Stereo-Flow mode

core::DetectorParams flow_params() {
  core::DetectorParams p;
  p.mode = core::Mode::kStereoFlow;
  return p;
}

/// Stereo-Flow with these gaps and a signal on from the first dangerous frame (no confirmation
/// over frames either: the tests look at each frame's labelling).
core::DetectorParams flow_params_at_once(std::vector<int> gaps) {
  core::DetectorParams p = flow_params();
  p.scene_flow.gaps = std::move(gaps);
  p.signal.on_k = 1;
  p.signal.on_n = 1;
  p.signal.confirm_frames = 1;
  return p;
}

/// The patch of kPatch moved by `shift_x` px since the last frame: backward flow (-shift_x, 0) on
/// it, zero elsewhere (the background does not move).
cv::Mat patch_flow(cv::Rect patch, float shift_x) {
  const core::Camera cam = camera();
  cv::Mat f(cam.height, cam.width, CV_32FC2, cv::Scalar(0, 0));
  f(patch).setTo(cv::Scalar(-shift_x, 0));
  return f;
}

TEST(DetectorStereoFlow, HeadOnPatchFiresWithItsVelocity) {
  core::DetectorParams params = flow_params();
  params.scene_flow.gaps = {1, 4};  // a fit window of 4 frames (0.4 s at 10 fps)
  Detector det(params, camera());
  cv::RNG rng(11);
  std::vector<core::Detection> out;
  for (int i = 0; i < 16; ++i) {
    // 6 m -> 2.25 m at 2.5 m/s; every point moves along its ray, so the flow is zero.
    const double z = 6.0 - 0.25 * i;
    FrameMaps maps{scene(z, rng, 0.1), i == 0 ? cv::Mat() : patch_flow(kPatch, 0.0f)};
    out.push_back(det.process(frame(i), maps));
  }
  EXPECT_FALSE(out[0].signal);
  EXPECT_EQ(cv::countNonZero(out[0].danger), 0);  // no history yet
  // The disparity grows by 0.36 px a frame, below min_delta_d_px: frame 1 is noise. Frames 2 and
  // 3 fit a chain short of the longest gap, doubted by the scatter of the patch's positions about
  // their line: the pixels' 0.1 px errors average out over the patch, so its approach stands
  // clear of the doubt at once (a fixed doubt of 0.6 px held it back until the window was full,
  // frame 4). The blob is confirmed on its second frame (3), and with on_k = 2 the signal is on
  // from frame 4 to the end.
  for (int i = 0; i < 16; ++i) EXPECT_EQ(out[i].signal, i >= 4) << "frame " << i;
  const core::Detection& last = out[15];
  ASSERT_TRUE(last.signal);
  EXPECT_TRUE(last.regions[1].fired);
  EXPECT_FALSE(last.regions[0].fired);
  ASSERT_EQ(last.obstacles.size(), 1u);
  const core::Obstacle& o = last.obstacles[0];
  // Pixels within edge_margin_px of the patch's border are not labelled.
  EXPECT_TRUE(kPatch.contains(o.bbox.tl()));
  EXPECT_LE(o.bbox.width, kPatch.width - 2 * params.scene_flow.edge_margin_px);
  ASSERT_TRUE(o.velocity.has_value());
  EXPECT_NEAR((*o.velocity)[2], -2.5, 0.3);
  EXPECT_LT(std::abs((*o.velocity)[0]), 0.5);
  EXPECT_LT(std::abs((*o.velocity)[1]), 0.5);
  ASSERT_TRUE(o.ttc_s.has_value());
  const double z = 6.0 - 0.25 * 15;
  EXPECT_NEAR(*o.ttc_s, (z - params.envelope.z_contact_m) / 2.5, 0.3);
}

// The point of the mode: a patch crossing at constant depth. Stereo mode flags its leading edge
// (the disparity there jumps from the background's to the patch's); Stereo-Flow mode follows the
// flow and finds a sideways motion.
TEST(DetectorStereoFlow, CrossingPatchNeverFiresWhereStereoModeDoes) {
  core::DetectorParams stereo_params;
  stereo_params.stereo.gaps = {1};
  // The thesis' Stereo mode: the leading edge moves by 6 px a frame, so confirmation over frames
  // would drop its strips (a new box every frame); without it they fire.
  stereo_params.signal.confirm_frames = 1;
  Detector flow_det(flow_params(), camera()), stereo_det(stereo_params, camera());
  cv::RNG rng(12);
  const core::Camera cam = camera();
  int stereo_alarms = 0;
  for (int i = 0; i < 16; ++i) {
    const cv::Rect patch(5 + 6 * i, 45, 40, 31);  // 2.4 m/s at 4 m
    // A wall 6 m away behind it, near enough for Stereo mode's max_growth rule to let the edge by.
    cv::Mat d(cam.height, cam.width, CV_32F, cv::Scalar(cam.disparity(6.0)));
    d(patch).setTo(cam.disparity(4.0));
    for (int y = 0; y < d.rows; ++y)
      for (int x = 0; x < d.cols; ++x)
        d.at<float>(y, x) += static_cast<float>(rng.uniform(-0.1, 0.1));
    const core::Detection f =
        flow_det.process(frame(i), {d, i == 0 ? cv::Mat() : patch_flow(patch, 6.0f)});
    EXPECT_FALSE(f.signal) << "frame " << i;
    EXPECT_EQ(cv::countNonZero(f.danger), 0) << "frame " << i;
    stereo_alarms += stereo_det.process(frame(i), {d, {}}).signal;
  }
  EXPECT_GT(stereo_alarms, 5);
}

TEST(DetectorStereoFlow, GapsNeedAnUnbrokenChainOfFlows) {
  core::DetectorParams params = flow_params_at_once({2});
  params.scene_flow.fit_velocity = false;  // one gap's own semantics
  Detector det(params, camera());
  cv::RNG rng(13);
  std::vector<bool> dangerous;
  for (int i = 0; i < 6; ++i) {
    const double z = 5.0 - 0.3 * i;
    // Frame 3 comes without flow (as after a dropped frame): gap 2 is unavailable at frames 3, 4.
    const bool no_flow = i == 0 || i == 3;
    const core::Detection d =
        det.process(frame(i), {scene(z, rng, 0.05), no_flow ? cv::Mat() : patch_flow(kPatch, 0)});
    dangerous.push_back(cv::countNonZero(d.danger) > 0);
  }
  EXPECT_FALSE(dangerous[0]);
  EXPECT_FALSE(dangerous[1]);  // one frame of history
  EXPECT_TRUE(dangerous[2]);
  EXPECT_FALSE(dangerous[3]);
  EXPECT_FALSE(dangerous[4]);
  EXPECT_TRUE(dangerous[5]);
}

// A dropped frame (index 3 never arrives) shortens the chain instead of restarting it: frame 4's
// flow leads to frame 2, so gap 2 compares with frame 2 over one flow and 0.2 s, and the patch
// stays dangerous; a chain restart would have left frames 4 and 5 without gap 2.
// With the velocity fit (default), the samples carry their real times too.
TEST(DetectorStereoFlow, DroppedFrameShortensTheChain) {
  for (bool fit : {false, true}) {
    core::DetectorParams params = flow_params_at_once({2});
    params.scene_flow.fit_velocity = fit;
    Detector det(params, camera());
    cv::RNG rng(14);
    std::vector<bool> dangerous;
    std::vector<double> ttc;
    for (int i : {0, 1, 2, 4, 5, 6}) {
      const double z = 5.0 - 0.3 * i;  // 3 m/s at 10 fps
      const core::Detection d =
          det.process(frame(i), {scene(z, rng, 0.05), i == 0 ? cv::Mat() : patch_flow(kPatch, 0)});
      dangerous.push_back(cv::countNonZero(d.danger) > 0);
      ttc.push_back(d.obstacles.empty() || !d.obstacles[0].ttc_s ? -1.0 : *d.obstacles[0].ttc_s);
    }
    EXPECT_FALSE(dangerous[0]) << "fit " << fit;
    // Gap 2 alone needs two frames; the fit's first pair (frame 1, 0.1 s) shows no scatter to
    // measure its error by, so the chain short of its window is not trusted yet.
    EXPECT_FALSE(dangerous[1]) << "fit " << fit;
    for (size_t j = 2; j < dangerous.size(); ++j)
      EXPECT_TRUE(dangerous[j]) << "arrival " << j << " fit " << fit;
    // The time span is the real one: frame 4 (z = 3.8 m) against frame 2 (4.4 m) over 0.2 s.
    EXPECT_NEAR(ttc[3], (3.8 - params.envelope.z_contact_m) / 3.0, 0.25) << "fit " << fit;
  }
}

// Over the first frames of a chain the velocity fit is dominated by the disparity error
// (simulated thin-pole: a 0.6 px step of the matcher within 4 frames at 7.6 m read -5.8 m/s for
// a true -1.4, an alarm 4 s early), so until the chain reaches the longest gap the envelope test
// doubts each surface's velocity by the scatter of its own positions about its fitted line
// (startup_doubt_se standard errors). Here (f B = 50 px m, 10 fps, gaps 1 and 10): a static
// patch 8 m away whose disparity steps up by 1 px at frame 2 fits -6 m/s over 0.2 s (TTC 1.1 s)
// and alarms when the first frames are trusted, never when doubted (the step leaves its
// positions as far off their line as the motion it fits); a patch 5 m away at 3 m/s lies on its
// line within the pixels' noise and is trusted from its third frame, the first with a scatter
// to measure.
TEST(DetectorStereoFlow, TheFirstFramesOfAChainAlarmOnlyOnAnApproachClearOfTheirNoise) {
  auto dangerous_frames = [](double doubt_se, auto depth) {
    core::DetectorParams params = flow_params_at_once({1, 10});
    params.scene_flow.startup_doubt_se = doubt_se;
    Detector det(params, camera());
    cv::RNG rng(15);
    std::vector<int> frames;
    for (int i = 0; i < 8; ++i) {
      const core::Detection d = det.process(
          frame(i), {scene(depth(i), rng, 0.05), i == 0 ? cv::Mat() : patch_flow(kPatch, 0)});
      if (cv::countNonZero(d.danger) > 0) frames.push_back(i);
    }
    return frames;
  };
  const double fb = camera().focal_px * camera().baseline_m;
  auto stepped = [fb](int i) { return i < 2 ? 8.0 : fb / (fb / 8.0 + 1.0); };
  auto approaching = [](int i) { return 5.0 - 0.3 * i; };
  const std::vector<int> trusted = dangerous_frames(0.0, stepped);
  ASSERT_FALSE(trusted.empty());
  EXPECT_EQ(trusted.front(), 2);
  EXPECT_TRUE(dangerous_frames(2.0, stepped).empty());
  const std::vector<int> caught = dangerous_frames(2.0, approaching);
  ASSERT_FALSE(caught.empty());
  EXPECT_EQ(caught.front(), 2);
  EXPECT_EQ(caught.back(), 7);
}

// The same after frames dropped at the start of a stream (1 and 2 never arrive): the chain's
// samples carry their real times, and a well-measured approach is trusted as soon as it has three
// of them. A patch 8 m away at 2.5 m/s (TTC 3.0 s at frame 0) is dangerous from frame 4 (samples
// at 0, 0.3 and 0.4 s); a fixed doubt of 0.6 px held it back until frame 8, as for a far
// approach the error it assumed is most of the motion of the first frames. The stepped patch of
// the test above stays safe.
TEST(DetectorStereoFlow,
     AfterFramesDroppedAtTheStartAWellMeasuredApproachIsTrustedAtItsThirdSample) {
  auto dangerous_frames = [](auto depth) {
    Detector det(flow_params_at_once({1, 10}), camera());
    cv::RNG rng(16);
    std::vector<int> frames;
    for (int i : {0, 3, 4, 5, 6, 7, 8, 9}) {
      const core::Detection d = det.process(
          frame(i), {scene(depth(i), rng, 0.05), i == 0 ? cv::Mat() : patch_flow(kPatch, 0)});
      if (cv::countNonZero(d.danger) > 0) frames.push_back(i);
    }
    return frames;
  };
  const std::vector<int> caught = dangerous_frames([](int i) { return 8.0 - 0.25 * i; });
  ASSERT_FALSE(caught.empty());
  EXPECT_EQ(caught.front(), 4);
  EXPECT_EQ(caught.back(), 9);
  const double fb = camera().focal_px * camera().baseline_m;
  EXPECT_TRUE(
      dangerous_frames([fb](int i) { return i < 4 ? 8.0 : fb / (fb / 8.0 + 1.0); }).empty());
}

TEST(DetectorStereoFlow, BadFlowIsAnInputError) {
  Detector det(flow_params(), camera());
  cv::RNG rng(14);
  det.process(frame(0), {scene(5.0, rng), {}});
  EXPECT_THROW(det.process(frame(1), {scene(5.0, rng), cv::Mat(121, 161, CV_32FC1)}),
               core::InputError);
  EXPECT_THROW(det.process(frame(1), {scene(5.0, rng), cv::Mat(120, 161, CV_32FC2)}),
               core::InputError);
}

TEST(Detector, DisparitySizeChangeIsAnInputError) {
  Detector det(core::DetectorParams{}, camera());
  det.process(frame(0), {cv::Mat(121, 161, CV_32F, cv::Scalar(5.0f)), {}});
  EXPECT_THROW(det.process(frame(1), {cv::Mat(120, 161, CV_32F, cv::Scalar(5.0f)), {}}),
               core::InputError);
}

TEST(FrameKernels, DisparityMatchesBmAndMismatchedFramesAreRejected) {
  const auto pair = test::shifted_pair({201, 97}, 9.0f, 21);
  core::StereoFrame f = frame(0);
  f.left = pair.left;
  f.right = pair.right;
  core::DetectorParams params;
  params.bm.left_band = false;     // StereoBM leaves the band unmatched
  params.bm.coarse_fill = false;   // and its holes
  cv::Mat disp, flow;
  check_frame(f);
  allocate_maps(f.left.size(), /*with_flow=*/false, disp, flow);
  disparity_rows(f, params, disp, cv::Range::all());
  disparity_finish(f, params, disp);
  ASSERT_EQ(disp.size(), pair.left.size());
  EXPECT_NEAR(disp.at<float>(48, 150), 9.0f, 0.25f);
  cv::Mat whole;
  match_bm(f.left, f.right, params.bm, whole);
  EXPECT_EQ(cv::countNonZero(disp != whole), 0);
  f.right = pair.right(cv::Rect(0, 0, 200, 97));
  EXPECT_THROW(check_frame(f), core::InputError);
}

// Mismatch-like blobs: every other frame a patch 11 m away flashes up in front of a 20 m wall, at
// one of two places in the centre region, so that no blob is seen twice in a row. Each frame with
// a blob is dangerous by itself (Stereo mode: the disparity grew by 2 px within 0.1 s); the
// region hysteresis alone (2 of 3 frames) lets them fire, while confirmation keeps them quiet
// and still lets a patch that stays fire.
TEST(Detector, BlobsSeenForOneFrameRaiseNoAlarm) {
  const core::Camera cam = camera();
  auto wall_with = [&cam](std::optional<cv::Rect> patch) {
    cv::Mat d(cam.height, cam.width, CV_32F, cv::Scalar(cam.disparity(20.0)));
    d(cv::Rect(0, 0, 20, cam.height)).setTo(-1.0f);
    if (patch) d(*patch).setTo(cam.disparity(11.0));
    return d;
  };
  const cv::Rect a(55, 52, 20, 17), b(85, 52, 20, 17);
  auto flashes = [&](int confirm_frames) {
    core::DetectorParams params;
    params.mode = core::Mode::kStereo;
    params.signal.confirm_frames = confirm_frames;
    Detector det(params, cam);
    int alarms = 0;
    for (int i = 0; i < 16; ++i) {
      std::optional<cv::Rect> patch;
      if (i >= 6 && i % 2 == 0) patch = (i % 4 == 0) ? a : b;
      alarms += det.process(frame(i), {wall_with(patch), {}}).signal ? 1 : 0;
    }
    return alarms;
  };
  EXPECT_GT(flashes(1), 0);  // what the test guards against
  EXPECT_EQ(flashes(2), 0);

  // A patch that stays and comes nearer fires (as in ApproachingPatchFiresAfterHysteresis...).
  core::DetectorParams params;
  params.mode = core::Mode::kStereo;
  Detector det(params, cam);
  cv::RNG rng(5);
  int alarms = 0;
  for (int i = 0; i < 16; ++i)
    alarms += det.process(frame(i), {scene(8.0 - 0.25 * i, rng, 0.1), {}}).signal ? 1 : 0;
  EXPECT_GE(alarms, 8);
}

}  // namespace
}  // namespace sg::vision
