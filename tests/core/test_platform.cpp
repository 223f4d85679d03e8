#include <gtest/gtest.h>

#include "sg/core/error.hpp"
#include "sg/core/platform.hpp"

namespace sg::core {
namespace {

TEST(Platform, CarPresetSetsItsEnvelopeRangeAndDepthLimits) {
  DetectorParams p;
  apply_platform("car", p);
  EXPECT_DOUBLE_EQ(p.envelope.half_width_m, 1.0);
  EXPECT_DOUBLE_EQ(p.envelope.z_contact_m, 2.0);
  EXPECT_EQ(p.bm.num_disparities, 128);
  EXPECT_DOUBLE_EQ(p.scene_flow.z_max_m, 60.0);
  EXPECT_DOUBLE_EQ(p.stereo.z_max_m, 40.0);
  const Envelope e = platform_envelope("car");
  EXPECT_DOUBLE_EQ(e.y_top_m, p.envelope.y_top_m);
}

TEST(Platform, PresetsOverwriteOneAnotherAndRobotIsTheDefaults) {
  DetectorParams p;
  apply_platform("car", p);
  apply_platform("robot", p);
  const DetectorParams defaults;
  EXPECT_DOUBLE_EQ(p.envelope.half_width_m, defaults.envelope.half_width_m);
  EXPECT_DOUBLE_EQ(p.envelope.z_contact_m, defaults.envelope.z_contact_m);
  EXPECT_EQ(p.bm.num_disparities, defaults.bm.num_disparities);
  EXPECT_DOUBLE_EQ(p.scene_flow.z_max_m, defaults.scene_flow.z_max_m);
  EXPECT_DOUBLE_EQ(p.scene_flow.ground.z_max_m, defaults.scene_flow.ground.z_max_m);
  // "" leaves everything as it is; every preset validates.
  p.envelope.half_width_m = 0.7;
  apply_platform("", p);
  EXPECT_DOUBLE_EQ(p.envelope.half_width_m, 0.7);
  for (const std::string& name : platform_names()) {
    DetectorParams q;
    apply_platform(name, q);
    Camera wide;
    wide.width = 960;
    EXPECT_TRUE(validate(q, wide).empty()) << name;
  }
}

TEST(Platform, UnknownNameListsTheKnownOnes) {
  DetectorParams p;
  try {
    apply_platform("boat", p);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("boat"), std::string::npos) << what;
    EXPECT_NE(what.find("walker"), std::string::npos) << what;
  }
}

TEST(AdaptToCamera, TheRangeReachesTheContactPlane) {
  // The shared robot recording: f B = 567.2 px x 0.0922 m = 52.3 px m; contact at 0.5 m needs
  // a disparity of 104.6 px, so 7 x 16 = 112 (64 measured only down to 0.83 m).
  Camera robot;
  robot.focal_px = 567.2;
  robot.baseline_m = 0.092226;
  robot.fps = 15.0;
  DetectorParams p;
  const CameraFit fit = adapt_to_camera(p, robot);
  EXPECT_EQ(p.bm.num_disparities, 112);
  EXPECT_LE(fit.near_m, p.envelope.z_contact_m);
  EXPECT_GT(robot.depth(p.bm.num_disparities - 17), p.envelope.z_contact_m);  // 96 is too few
  EXPECT_TRUE(fit.warning.empty());
  EXPECT_TRUE(validate(p, robot).empty());
  // A tiny board (f B = 7.1 px m): 16 disparities reach 0.47 m.
  Camera board;
  board.width = 122;
  board.height = 94;
  board.focal_px = 118.0;
  board.baseline_m = 0.06;
  board.fps = 6.9;
  DetectorParams q;
  adapt_to_camera(q, board);
  EXPECT_EQ(q.bm.num_disparities, 16);
  EXPECT_TRUE(validate(q, board).empty());
}

TEST(AdaptToCamera, ACappedRangeSaysWhatItCannotMeasure) {
  Camera wide_baseline;
  wide_baseline.baseline_m = 0.5;  // f B = 250 px m: 500 px for 0.5 m
  DetectorParams p;
  const CameraFit fit = adapt_to_camera(p, wide_baseline);
  EXPECT_EQ(p.bm.num_disparities, kMaxDerivedDisparities);
  EXPECT_NEAR(fit.near_m, 250.0 / (kMaxDerivedDisparities - 1), 1e-9);
  EXPECT_NE(fit.warning.find("0.98 m"), std::string::npos) << fit.warning;
  // Below the image width too: a 200 px wide image gets at most 96.
  Camera narrow = wide_baseline;
  narrow.width = 200;
  DetectorParams q;
  adapt_to_camera(q, narrow);
  EXPECT_EQ(q.bm.num_disparities, 96);
  EXPECT_TRUE(validate(q, narrow).empty());
}

TEST(AdaptToCamera, SizesScaleWithTheImageAndGapsKeepTheirSeconds) {
  const DetectorParams defaults;
  Camera reference;  // 640x480 at 30 fps: pixel sizes and gaps as written
  DetectorParams p;
  adapt_to_camera(p, reference);
  EXPECT_EQ(p.signal.min_area_px, defaults.signal.min_area_px);
  EXPECT_EQ(p.signal.region_min_px, defaults.signal.region_min_px);
  EXPECT_EQ(p.scene_flow.edge_margin_px, defaults.scene_flow.edge_margin_px);
  EXPECT_EQ(p.scene_flow.gaps, defaults.scene_flow.gaps);
  EXPECT_EQ(p.stereo.gaps, defaults.stereo.gaps);

  Camera big = reference;  // 4x the pixels at 60 fps
  big.width = 1280;
  big.height = 960;
  big.fps = 60.0;
  DetectorParams q;
  adapt_to_camera(q, big);
  EXPECT_EQ(q.signal.min_area_px, 4 * defaults.signal.min_area_px);
  EXPECT_EQ(q.scene_flow.edge_margin_px, defaults.scene_flow.edge_margin_px);  // never grows
  EXPECT_EQ(q.scene_flow.gaps, (std::vector<int>{2, 8, 20, 40}));

  Camera small = reference;  // the 122x94 board at 6.9 fps
  small.width = 122;
  small.height = 94;
  small.fps = 6.9;
  DetectorParams r;
  adapt_to_camera(r, small);
  EXPECT_EQ(r.signal.min_area_px, 16);  // 150 x 0.037 = 5.6 px is below the floor
  EXPECT_EQ(r.scene_flow.edge_margin_px, defaults.bm.block_size / 2);
  EXPECT_EQ(r.scene_flow.gaps, (std::vector<int>{1, 2, 5}));  // 1, 0.9, 2.3, 4.6 frames
  EXPECT_EQ(r.stereo.gaps, (std::vector<int>{1, 3}));         // 0.2, 1.2, 3.5 frames
  // The hysteresis keeps its time, at least a frame: at 60 fps on 4 of 6 frames, off after 6;
  // at 6.9 fps each frame decides (a frame is 0.14 s, more than the 0.1 s written for 30 fps).
  EXPECT_EQ(q.signal.on_k, 4);
  EXPECT_EQ(q.signal.on_n, 6);
  EXPECT_EQ(q.signal.off_m, 6);
  EXPECT_EQ(q.signal.severity_off_frames, 10);
  EXPECT_EQ(r.signal.on_k, 1);
  EXPECT_EQ(r.signal.on_n, 1);
  EXPECT_EQ(r.signal.off_m, 1);
  EXPECT_EQ(p.signal.on_k, defaults.signal.on_k);
  EXPECT_EQ(p.signal.off_m, defaults.signal.off_m);
  EXPECT_TRUE(validate(r, small).empty());
}

TEST(AdaptToCamera, TheBlockKeepsItsAngleAboveTheReferenceWidth) {
  const int block = DetectorParams{}.bm.block_size;
  ASSERT_EQ(block, 11);
  const auto block_at = [](int width, int height) {
    Camera camera;
    camera.width = width;
    camera.height = height;
    DetectorParams p;
    adapt_to_camera(p, camera);
    EXPECT_TRUE(validate(p, camera).empty()) << width << "x" << height;
    return p.bm.block_size;
  };
  EXPECT_EQ(block_at(640, 480), 11);
  EXPECT_EQ(block_at(752, 480), 13);   // 12.9
  EXPECT_EQ(block_at(848, 480), 15);   // 14.6
  EXPECT_EQ(block_at(1280, 720), 21);  // 22: the odd size below
  EXPECT_EQ(block_at(1920, 1080), kMaxDerivedBlock);
  EXPECT_EQ(block_at(320, 240), 11);  // narrower images keep it
  EXPECT_EQ(block_at(122, 94), 11);
  // The largest derived block fits the fast matcher at the largest prefilter cap.
  Camera wide;
  wide.width = 1920;
  wide.height = 1080;
  DetectorParams p;
  adapt_to_camera(p, wide);
  p.bm.prefilter_cap = 63;
  EXPECT_TRUE(validate(p, wide).empty());
  // A block set larger than the derived one stays.
  DetectorParams q;
  q.bm.block_size = 25;
  adapt_to_camera(q, wide);
  EXPECT_EQ(q.bm.block_size, 25);
}

}  // namespace
}  // namespace sg::core
