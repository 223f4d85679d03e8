// Ego-rotation compensation (vision/ego_motion.hpp) and its effect on the Stereo-Flow labelling.
// The scenes come from the simulator's exact ground truth (disparity and backward flow), so the
// tests isolate the compensation from matching and flow errors.
#include <gtest/gtest.h>

#include <cmath>

#include "sg/sim/renderer.hpp"
#include "sg/vision/detector.hpp"
#include "sg/vision/ego_motion.hpp"

namespace sg::vision {
namespace {

constexpr double kDeg = CV_PI / 180.0;

/// Static boxes around a camera that turns at `yaw_dps` while moving forward at `speed_mps`
/// (world +Z); those on the right stand 1.1-1.9 m beside the path.
sim::Scenario static_scene(double yaw_dps, double speed_mps) {
  sim::Scenario s;
  s.name = "static-turn";
  s.frames = 36;
  s.noise_sigma = 0.0;
  s.camera_motion.yaw_rate_dps = yaw_dps;
  s.ego_velocity_mps = {0, 0, speed_mps};
  const double xs[] = {-2.0, 1.5, 1.5, 1.5, -1.6};
  const double zs[] = {5.0, 7.0, 8.5, 10.0, 12.0};
  for (int i = 0; i < 5; ++i) {
    sim::Box b;
    b.id = i + 1;
    b.size_m = {0.8, 1.6, 0.6};
    b.position_m = {xs[i], s.height_m - 0.8, zs[i]};
    b.texture_seed = static_cast<std::uint32_t>(50 + i);
    s.obstacles.push_back(b);
  }
  return s;
}

TEST(EgoMotion, RecoversRotationAndTranslationFromExactFlow) {
  const sim::Scenario s = static_scene(30.0, 1.5);
  const sim::Renderer r(s);
  const sim::RenderedFrame f = r.render(10);
  const EgoMotion m = estimate_ego_motion(f.maps.flow, f.maps.disparity, s.camera);
  ASSERT_TRUE(m.valid);
  // Per frame: yaw 1 deg to the right; the camera moves 5 cm along world +Z (ego velocity is in
  // the world frame), which the camera, turned by 10 deg at frame 10, sees as 5 cm along
  // (-sin 10, 0, cos 10): a static point was that much farther a frame ago (first order).
  EXPECT_NEAR(m.rotation[1], 1.0 * kDeg, 0.02 * kDeg);
  EXPECT_NEAR(m.rotation[0], 0.0, 0.02 * kDeg);
  EXPECT_NEAR(m.rotation[2], 0.0, 0.02 * kDeg);
  EXPECT_NEAR(m.translation[2], 0.05 * std::cos(10 * kDeg), 0.002);
  EXPECT_NEAR(m.translation[0], -0.05 * std::sin(10 * kDeg), 0.002);
  EXPECT_NEAR(m.translation[1], 0.0, 0.002);
  // derotation undoes the rotation: it turns frame i-1's optical axis into frame i's coordinates.
  const cv::Matx33d rel = sim::camera_rotation(s.camera_motion, 10 / 30.0).t() *
                          sim::camera_rotation(s.camera_motion, 9 / 30.0);
  EXPECT_LT(cv::norm(derotation(m) - rel), 1e-3);
}

TEST(EgoMotion, OutliersDoNotBendTheEstimate) {
  const sim::Scenario s = static_scene(-20.0, 0.0);
  const sim::RenderedFrame f = sim::Renderer(s).render(5);
  cv::Mat flow = f.maps.flow.clone();
  flow(cv::Rect(100, 100, 150, 150)).setTo(cv::Scalar(12.0, -7.0));  // a moving object
  const EgoMotion m = estimate_ego_motion(flow, f.maps.disparity, s.camera);
  ASSERT_TRUE(m.valid);
  EXPECT_NEAR(m.rotation[1], -20.0 / 30.0 * kDeg, 0.03 * kDeg);
  // Too few valid pixels: no estimate, and derotation is the identity.
  const cv::Mat invalid(f.maps.disparity.size(), CV_32F, cv::Scalar(-1));
  const EgoMotion none = estimate_ego_motion(flow, invalid, s.camera);
  EXPECT_FALSE(none.valid);
  EXPECT_EQ(derotation(none), cv::Matx33d::eye());
}

/// Dangerous pixels over the frames of `s`, the Stereo-Flow detector fed the exact maps.
int dangerous_pixels(const sim::Scenario& s, bool compensate) {
  core::DetectorParams p;
  p.mode = core::Mode::kStereoFlow;
  p.scene_flow.compensate_rotation = compensate;
  Detector det(p, s.camera);
  const sim::Renderer r(s);
  int total = 0;
  for (int i = 0; i < s.frames; ++i) {
    const sim::RenderedFrame f = r.render(i);
    total += cv::countNonZero(det.process(f.frame, {f.maps.disparity, f.maps.flow}).danger);
  }
  return total;
}

TEST(EgoMotion, PureYawOverAStaticSceneGivesNoDangerousPixel) {
  EXPECT_EQ(dangerous_pixels(static_scene(30.0, 0.0), true), 0);
  EXPECT_EQ(dangerous_pixels(static_scene(-30.0, 0.0), true), 0);
}

TEST(EgoMotion, YawWhileDrivingPastBoxesIsNotAnApproachOnceCompensated) {
  // Driving at 3 m/s while turning right at 10 deg/s: in the turning camera frame the boxes on
  // the right sweep sideways at yaw rate x depth (0.9 m/s at 5 m) and look as if they cut into
  // the envelope. Without the rotation they come straight at the camera, beside it.
  const sim::Scenario s = static_scene(10.0, 3.0);
  EXPECT_GT(dangerous_pixels(s, false), 0);
  EXPECT_EQ(dangerous_pixels(s, true), 0);
}

}  // namespace
}  // namespace sg::vision
