// Camera rotation, thin and floating objects, accelerating boxes and car cameras in the simulator,
// checked against analytic ground truth.
#include <gtest/gtest.h>

#include <cmath>

#include "sg/core/platform.hpp"
#include "sg/sim/renderer.hpp"

namespace sg::sim {
namespace {

constexpr double kDeg = CV_PI / 180.0;

/// An empty scene (ground and far wall only) for the default camera, without noise.
Scenario empty_scene() {
  Scenario s;
  s.name = "empty";
  s.frames = 30;
  s.noise_sigma = 0.0;
  return s;
}

TEST(CameraMotion, RotationIsIdentityWithoutMotionAndFollowsTheDocumentedAxes) {
  const CameraMotion none;
  EXPECT_FALSE(none.rotates());
  EXPECT_LT(cv::norm(camera_rotation(none, 1.7) - cv::Matx33d::eye()), 1e-15);
  CameraMotion yaw;
  yaw.yaw_rate_dps = 90.0;
  // After 1 s of yaw +90 deg/s the optical axis (camera +Z) points along world +X.
  const cv::Vec3d axis = camera_rotation(yaw, 1.0) * cv::Vec3d(0, 0, 1);
  EXPECT_NEAR(axis[0], 1.0, 1e-12);
  EXPECT_NEAR(axis[2], 0.0, 1e-12);
  CameraMotion pitch;
  pitch.pitch_amplitude_deg = 10.0;
  pitch.oscillation_hz = 1.0;
  // At t = 0.25 s the pitch peaks at +10 deg: the axis looks up (world -Y, since y is down).
  const cv::Vec3d up = camera_rotation(pitch, 0.25) * cv::Vec3d(0, 0, 1);
  EXPECT_NEAR(up[1], -std::sin(10.0 * kDeg), 1e-12);
}

TEST(CameraMotion, PitchedAndYawedCameraSeesTheGroundPlaneAnalytically) {
  // At t = 0.2 s with 1.25 Hz the pitch is at its +4 deg peak; yaw (20 deg/s) does not change the
  // ground's disparity. The ray of row y has world direction Y = cos(p) (y - cy) / f - sin(p)
  // per unit of camera depth, so the ground at height h gives d = f B (cos(p) (y - cy) / f -
  // sin(p)) / h.
  Scenario s = empty_scene();
  s.camera_motion.yaw_rate_dps = 20.0;
  s.camera_motion.pitch_amplitude_deg = 4.0;
  s.camera_motion.oscillation_hz = 1.25;
  const Renderer r(s);
  const RenderedFrame f = r.render(6);  // t = 6 / 30 = 0.2 s
  const core::Camera& c = s.camera;
  const double p = 4.0 * kDeg;
  int checked = 0;
  for (int y = 300; y < c.height; y += 20) {
    const double expected = c.focal_px * c.baseline_m *
                            (std::cos(p) * (y - c.cy) / c.focal_px - std::sin(p)) / s.height_m;
    for (int x : {0, 150, 320, 639}) {
      EXPECT_NEAR(f.maps.disparity.at<float>(y, x), expected, 1e-4 * expected) << x << "," << y;
      ++checked;
    }
  }
  EXPECT_GT(checked, 20);
}

TEST(CameraMotion, PureYawFlowIsTheRotationHomographyWhateverTheDepth) {
  // Turning in place: the backward flow of every static point (ground, wall, box) is the
  // depth-independent map p -> K R_prev^T R K^-1 p.
  Scenario s = empty_scene();
  s.camera_motion.yaw_rate_dps = 30.0;
  Box b;
  b.size_m = {1.0, 1.5, 0.5};
  b.position_m = {0.5, 0.45, 4.0};
  s.obstacles.push_back(b);
  const Renderer r(s);
  const int i = 10;
  const RenderedFrame f = r.render(i);
  const cv::Matx33d rel = camera_rotation(s.camera_motion, (i - 1) / 30.0).t() *
                          camera_rotation(s.camera_motion, i / 30.0);
  const core::Camera& c = s.camera;
  int box_pixels = 0;
  for (int y = 5; y < c.height; y += 17)
    for (int x = 3; x < c.width; x += 19) {
      if (f.maps.disparity.at<float>(y, x) <= 0) continue;  // sky
      const cv::Vec3d ray = rel * cv::Vec3d((x - c.cx) / c.focal_px, (y - c.cy) / c.focal_px, 1);
      const cv::Vec2f flow = f.maps.flow.at<cv::Vec2f>(y, x);
      EXPECT_NEAR(x + flow[0], c.cx + c.focal_px * ray[0] / ray[2], 1e-3) << x << "," << y;
      EXPECT_NEAR(y + flow[1], c.cy + c.focal_px * ray[1] / ray[2], 1e-3) << x << "," << y;
      box_pixels += f.maps.ids.at<std::uint16_t>(y, x) == 1;
    }
  EXPECT_GT(box_pixels, 5);
  // Turning right, the centre pixel was f tan(1 deg) = 8.7 px further right a frame earlier.
  EXPECT_NEAR(f.maps.flow.at<cv::Vec2f>(240, 320)[0], 500.0 * std::tan(1.0 * kDeg), 0.05);
}

TEST(CameraMotion, TurningInPlaceNeverCollides) {
  const Renderer r(builtin_scenario("turning"));
  for (int i = 0; i < r.scenario().frames; i += 7)
    for (const auto& o : r.truth(i).obstacles) EXPECT_FALSE(o.colliding) << "frame " << i;
}

TEST(CameraMotion, FollowingTheHeadingDrivesAnArcThatTheTruthFollowsToo) {
  // 10 m/s turning right at 20 deg/s: a circle of radius R = v / w about (R, 0, 0).
  Scenario s = empty_scene();
  s.ego_velocity_mps = {0, 0, 10.0};
  s.camera_motion.yaw_rate_dps = 20.0;
  s.ego_follows_heading = true;
  const double w = 20.0 * kDeg, radius = 10.0 / w;
  for (double t : {0.0, 0.5, 1.7, 4.0}) {
    // The closed form against a fine sum of the heading-turned velocity.
    cv::Vec3d sum(0, 0, 0);
    constexpr int kSteps = 20000;
    for (int i = 0; i < kSteps; ++i) {
      const double tau = (i + 0.5) * t / kSteps;
      sum += camera_rotation(s.camera_motion, tau) * s.ego_velocity_mps * (t / kSteps);
    }
    const cv::Vec3d p = ego_position(s, t);
    EXPECT_LT(cv::norm(p - sum), 1e-6) << t;
    EXPECT_NEAR(cv::norm(p - cv::Vec3d(radius, 0, 0)), radius, 1e-9) << t;
  }
  s.ego_follows_heading = false;
  EXPECT_LT(cv::norm(ego_position(s, 1.7) - cv::Vec3d(0, 0, 17.0)), 1e-12);

  // A post on the arc 60 deg on (30 m of arc, 2.8 s) collides; one as far ahead on the straight
  // line, 14 m outside the bend by then, does not: the ground truth follows the arc.
  s.ego_follows_heading = true;
  s.envelope.horizon_s = 3.0;
  const double a = 60.0 * kDeg;
  Box on_arc;
  on_arc.id = 1;
  on_arc.size_m = {0.2, 2.0, 0.2};
  on_arc.position_m = {radius * (1 - std::cos(a)), s.height_m - 1.0, radius * std::sin(a)};
  Box straight_ahead = on_arc;
  straight_ahead.id = 2;
  straight_ahead.position_m[0] = 0.0;
  const core::ObstacleTruth hit = box_collision(s, on_arc, 0.0);
  ASSERT_TRUE(hit.colliding);
  EXPECT_NEAR(*hit.ttc_s, (a * radius - 0.1 - s.envelope.z_contact_m) / 10.0, 0.1);
  EXPECT_FALSE(box_collision(s, straight_ahead, 0.0).colliding);
  s.ego_follows_heading = false;  // the camera crabs straight on while it turns
  EXPECT_FALSE(box_collision(s, on_arc, 0.0).colliding);
}

TEST(ThinObjects, PoleWidthInPixelsIsFocalTimesWidthOverDistance) {
  // A 5 cm pole whose front face is 5 m ahead: f w / Z = 500 * 0.05 / 5 = 5 px.
  for (double z : {5.0, 10.0}) {
    Scenario s = empty_scene();
    Box pole;
    pole.size_m = {0.05, 3.0, 0.05};
    pole.position_m = {0.0, s.height_m - 1.5, z + 0.025};
    s.obstacles.push_back(pole);
    const RenderedFrame f = Renderer(s).render(0);
    const double expected = s.camera.focal_px * 0.05 / z;
    for (int y : {170, 240, 290}) {
      const int width = cv::countNonZero(f.maps.ids.row(y) == 1);
      EXPECT_GE(width, std::floor(expected)) << z << " row " << y;
      EXPECT_LE(width, std::ceil(expected) + 1) << z << " row " << y;
    }
    // Its disparity is that of the front face.
    EXPECT_NEAR(f.maps.disparity.at<float>(240, 320), s.camera.disparity(z), 1e-4);
  }
}

TEST(ThinObjects, OverhangHasNothingBelowItAndCollidesWithTheWalker) {
  const Scenario s = builtin_scenario("overhang");
  const Renderer r(s);
  const RenderedFrame f = r.render(100);
  // Columns through the bar: bar pixels above, then ground below (id 0, valid disparity).
  const int x = static_cast<int>(s.camera.cx + 10);
  int bar_rows = 0, last_bar_row = -1;
  for (int y = 0; y < s.camera.height; ++y)
    if (f.maps.ids.at<std::uint16_t>(y, x) == 1) {
      ++bar_rows;
      last_bar_row = y;
    }
  ASSERT_GT(bar_rows, 5);
  EXPECT_LT(last_bar_row, s.camera.cy);  // above the horizon: head height
  for (int y = last_bar_row + 1; y < s.camera.height; ++y)
    EXPECT_EQ(f.maps.ids.at<std::uint16_t>(y, x), 0) << y;
  EXPECT_TRUE(r.truth(s.frames - 1).obstacles[0].colliding);
  EXPECT_FALSE(r.truth(0).obstacles[0].colliding);
}

TEST(CameraMotion, AFixedPitchTiltsTheGroundLikeTheSway) {
  // The formula of the test above with a mounting pitch of -3 deg (looking down) and no sway.
  Scenario s = empty_scene();
  s.camera_motion.pitch_deg = -3.0;
  ASSERT_TRUE(s.camera_motion.rotates());
  const RenderedFrame f = Renderer(s).render(0);
  const core::Camera& c = s.camera;
  const double p = -3.0 * kDeg;
  for (int y = 260; y < c.height; y += 40) {
    const double expected = c.focal_px * c.baseline_m *
                            (std::cos(p) * (y - c.cy) / c.focal_px - std::sin(p)) / s.height_m;
    EXPECT_NEAR(f.maps.disparity.at<float>(y, 320), expected, 1e-4 * expected) << y;
  }
  // A fixed roll tilts the horizon: the ground's disparity differs between the two sides.
  s.camera_motion.pitch_deg = 0.0;
  s.camera_motion.roll_deg = 3.0;
  const RenderedFrame g = Renderer(s).render(0);
  EXPECT_GT(std::abs(g.maps.disparity.at<float>(400, 20) - g.maps.disparity.at<float>(400, 619)),
            1.0);
}

TEST(EgoMotion, PositionIsTheIntegralOfTheVelocityThroughTurnsAndSpeedChanges) {
  // Reference: Simpson's rule over ego_velocity; the closed form must agree.
  for (const bool heading : {false, true}) {
    Scenario s = empty_scene();
    s.ego_velocity_mps = {0.3, 0.0, 2.0};
    s.ego_follows_heading = heading;
    s.camera_motion.yaw_rate_dps = -17.0;
    s.ego_accelerations = {{0.4, {0.0, 0.1, -1.5}}, {1.1, {0.5, 0.0, 0.0}}, {1.9, {0, 0, 0}}};
    for (const double t : {-0.05, 0.3, 0.4, 1.0, 1.5, 2.5}) {
      const int n = 20000;
      const double h = t / n;
      cv::Vec3d sum(0, 0, 0);
      for (int i = 0; i <= n; ++i)
        sum += ego_velocity(s, i * h) * ((i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0));
      const cv::Vec3d reference = sum * (h / 3.0);
      EXPECT_LT(cv::norm(ego_position(s, t) - reference), 1e-6) << heading << " t " << t;
    }
  }
}

TEST(EgoMotion, TheTruthOfABrakingCameraUsesItsCurrentSpeed) {
  // From 2 m/s, braking at 1 m/s^2 from t = 0.5 s: at t = 1 s the camera has moved
  // 1 + 2 * 0.5 - 0.5 * 0.25 = 1.875 m and drives at 1.5 m/s. A box 6 m ahead (near face) is then
  // 6 - 1.875 - contact away: TTC = that / 1.5 (the braking is not foreseen, as a TTC is not).
  Scenario s = empty_scene();
  s.ego_velocity_mps = {0, 0, 2.0};
  s.ego_accelerations = {{0.5, {0, 0, -1.0}}, {2.5, {0, 0, 0}}};
  Box b;
  b.size_m = {0.6, 1.0, 0.4};
  b.position_m = {0.0, 0.5, 6.2};
  s.obstacles = {b};
  EXPECT_LT(cv::norm(ego_position(s, 1.0) - cv::Vec3d(0, 0, 1.875)), 1e-12);
  EXPECT_LT(cv::norm(ego_velocity(s, 1.0) - cv::Vec3d(0, 0, 1.5)), 1e-12);
  const core::ObstacleTruth o = box_collision(s, b, 1.0);
  ASSERT_TRUE(o.colliding);
  EXPECT_NEAR(*o.ttc_s, (6.0 - 1.875 - s.envelope.z_contact_m) / 1.5, 1e-9);
  // Stopped (from t = 2.5 s): nothing approaches, nothing collides.
  EXPECT_LT(cv::norm(ego_velocity(s, 3.0)), 1e-12);
  EXPECT_FALSE(box_collision(s, b, 3.0).colliding);
  // Turning as well (the stepped test): the same TTC within its 1 ms step.
  s.camera_motion.pitch_deg = 1e-9;  // rotates(), but the axes stay put
  const core::ObstacleTruth stepped = box_collision(s, b, 1.0);
  ASSERT_TRUE(stepped.colliding);
  EXPECT_NEAR(*stepped.ttc_s, *o.ttc_s, 1e-3);
}

TEST(MovingObjects, AccelerationPhasesIntegrateExactly) {
  Box b;
  b.position_m = {3.5, 0, 20};
  b.velocity_mps = {0, 0, 6};
  b.accelerations = {{1.0, {-2, 0, 0}}, {2.0, {0, 0, -4}}, {3.5, {0, 0, 0}}};
  // Before the first phase: constant velocity.
  EXPECT_LT(cv::norm(box_position(b, 0.5) - cv::Vec3d(3.5, 0, 23)), 1e-12);
  // t = 1.5: 0.5 s of -2 m/s^2 in X.
  EXPECT_LT(cv::norm(box_position(b, 1.5) - cv::Vec3d(3.5 - 0.25, 0, 29)), 1e-12);
  EXPECT_LT(cv::norm(box_velocity(b, 1.5) - cv::Vec3d(-1, 0, 6)), 1e-12);
  // t = 3: X coasts at -2 m/s from t = 2; Z brakes from 6 m/s for 1 s.
  EXPECT_LT(cv::norm(box_position(b, 3.0) - cv::Vec3d(3.5 - 1 - 2, 0, 20 + 12 + 6 - 2)), 1e-12);
  // t = 5: braking ended at 3.5 s with v_z = 0.
  EXPECT_LT(cv::norm(box_velocity(b, 5.0) - cv::Vec3d(-2, 0, 0)), 1e-12);
  EXPECT_NEAR(box_position(b, 5.0)[2], 20 + 12 + 6 * 1.5 - 2 * 1.5 * 1.5, 1e-12);
}

TEST(CarCamera, StoppedCarTtcIsGapOverSpeed) {
  // Car camera at 10 m/s, the stopped car's rear 40 m ahead, contact at 2 m (car envelope):
  // TTC(t) = (40 - 10 t - 2) / 10, GT alarm while it is <= 3 s.
  const Scenario s = builtin_scenario("car-stopped");
  EXPECT_EQ(s.platform, "car");
  EXPECT_DOUBLE_EQ(s.camera.focal_px, 600.0);
  EXPECT_DOUBLE_EQ(s.camera.baseline_m, 0.30);
  EXPECT_DOUBLE_EQ(s.envelope.z_contact_m, core::platform_envelope("car").z_contact_m);
  const Renderer r(s);
  for (int i = 0; i < s.frames; i += 5) {
    const double t = i / 30.0;
    const double ttc = (40.0 - 10.0 * t - 2.0) / 10.0;
    const core::ObstacleTruth o = box_collision(s, s.obstacles[0], t);
    EXPECT_EQ(o.colliding, ttc <= 3.0) << i;
    if (o.colliding) {
      EXPECT_NEAR(*o.ttc_s, ttc, 1e-9) << i;
    }
    EXPECT_FALSE(box_collision(s, s.obstacles[1], t).colliding) << i;  // the next lane
  }
  EXPECT_FALSE(r.truth(23).alarm);  // t = 0.767 s, TTC 3.03 s
  EXPECT_TRUE(r.truth(24).alarm);   // t = 0.8 s, TTC 3.0 s
}

TEST(CarCamera, CutInTtcUsesTheCurrentVelocity) {
  // car-cut-in: lateral motion ends at t = 2 s (X = 0.3 m), rear 16 m ahead closing at 4 m/s;
  // braking at 4 m/s^2 from t = 3 s. TTC at t = 2.5 s: (14 - 2) / 4 = 3 s; at t = 3.5 s the car
  // is 12 - 2 - 0.5 = 9.5 m ahead closing at 6 m/s: TTC (9.5 - 2) / 6 = 1.25 s.
  const Scenario s = builtin_scenario("car-cut-in");
  const Box& other = s.obstacles[0];
  EXPECT_NEAR(box_position(other, 2.0)[0], 0.3, 1e-12);
  const core::ObstacleTruth at_25 = box_collision(s, other, 2.5);
  ASSERT_TRUE(at_25.colliding);
  EXPECT_NEAR(*at_25.ttc_s, 3.0, 1e-9);
  EXPECT_FALSE(box_collision(s, other, 2.4).colliding);
  // While it pulls in, its lateral velocity carries it past the envelope at constant velocity.
  EXPECT_FALSE(box_collision(s, other, 1.5).colliding);
  const core::ObstacleTruth at_35 = box_collision(s, other, 3.5);
  ASSERT_TRUE(at_35.colliding);
  EXPECT_NEAR(*at_35.ttc_s, 1.25, 1e-9);
}

}  // namespace
}  // namespace sg::sim
