#include <gtest/gtest.h>

#include <random>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "sg/core/error.hpp"
#include "sg/vision/scene_flow.hpp"
#include "sg/vision/segment_motion.hpp"

namespace sg::vision {
namespace {

// ---------------------------------------------------------------------------------------------
// Bilinear sampling

/// 5 x 4 map, d(x, y) = 10 y + x, with (2, 1) invalid.
cv::Mat hand_map() {
  cv::Mat d(4, 5, CV_32F);
  for (int y = 0; y < d.rows; ++y)
    for (int x = 0; x < d.cols; ++x) d.at<float>(y, x) = static_cast<float>(10 * y + x);
  d.at<float>(1, 2) = -1.0f;
  return d;
}

TEST(SampleDisparity, ExactBilinearValue) {
  const cv::Mat d = hand_map();
  float v = 0;
  // Cell (3..4, 1..2): 13, 14, 23, 24 weighted (0.75, 0.25) in x and (0.5, 0.5) in y.
  ASSERT_TRUE(sample_disparity_bilinear(d, 3.25f, 1.5f, v));
  EXPECT_FLOAT_EQ(v, 0.5f * (0.75f * 13 + 0.25f * 14) + 0.5f * (0.75f * 23 + 0.25f * 24));
  ASSERT_TRUE(sample_disparity_bilinear(d, 0.5f, 2.25f, v));
  EXPECT_FLOAT_EQ(v, 0.75f * (0.5f * 20 + 0.5f * 21) + 0.25f * (0.5f * 30 + 0.5f * 31));
  ASSERT_TRUE(sample_disparity_bilinear(d, 4.0f, 3.0f, v));
  EXPECT_FLOAT_EQ(v, 34.0f);
}

TEST(SampleDisparity, InvalidNeighbourUsedFails) {
  const cv::Mat d = hand_map();
  float v = -7;
  // Each of the four cells around the invalid (2, 1) uses it.
  EXPECT_FALSE(sample_disparity_bilinear(d, 1.5f, 0.5f, v));  // as bottom-right neighbour
  EXPECT_FALSE(sample_disparity_bilinear(d, 2.5f, 0.5f, v));  // bottom-left
  EXPECT_FALSE(sample_disparity_bilinear(d, 1.5f, 1.5f, v));  // top-right
  EXPECT_FALSE(sample_disparity_bilinear(d, 2.5f, 1.5f, v));  // top-left
  EXPECT_FALSE(sample_disparity_bilinear(d, 2.0f, 1.0f, v));  // on it
  EXPECT_EQ(v, -7);                                           // untouched on failure
  // Zero-weight neighbours are not used: on column 1 or row 0 the invalid pixel is not read.
  ASSERT_TRUE(sample_disparity_bilinear(d, 1.0f, 1.5f, v));
  EXPECT_FLOAT_EQ(v, 16.0f);
  ASSERT_TRUE(sample_disparity_bilinear(d, 2.5f, 0.0f, v));
  EXPECT_FLOAT_EQ(v, 2.5f);
  ASSERT_TRUE(sample_disparity_bilinear(d, 2.0f, 2.5f, v));
  EXPECT_FLOAT_EQ(v, 27.0f);
}

TEST(SampleDisparity, OutsideTheImageFails) {
  const cv::Mat d = hand_map();
  const float w1 = 4.0f, h1 = 3.0f;
  const float eps = 1e-3f;
  float v = 0;
  // The four corners are inside ...
  EXPECT_TRUE(sample_disparity_bilinear(d, 0.0f, 0.0f, v));
  EXPECT_TRUE(sample_disparity_bilinear(d, w1, 0.0f, v));
  EXPECT_TRUE(sample_disparity_bilinear(d, 0.0f, h1, v));
  EXPECT_TRUE(sample_disparity_bilinear(d, w1, h1, v));
  // ... and a step past each side of each corner is outside.
  for (auto [x, y] : {std::pair{-eps, 0.0f}, {0.0f, -eps}, {w1 + eps, 0.0f}, {w1, -eps},
                      {-eps, h1}, {0.0f, h1 + eps}, {w1 + eps, h1}, {w1, h1 + eps}})
    EXPECT_FALSE(sample_disparity_bilinear(d, x, y, v)) << x << "," << y;
  EXPECT_FALSE(sample_disparity_bilinear(d, NAN, 1.0f, v));
  EXPECT_FALSE(sample_disparity_bilinear(d, 1.0f, INFINITY, v));
}

TEST(SampleDisparity, DepthEdgeFailsWithMaxStep) {
  cv::Mat d(3, 4, CV_32F, cv::Scalar(5.0f));
  d.at<float>(1, 2) = 7.0f;
  float v = 0;
  EXPECT_TRUE(sample_disparity_bilinear(d, 1.5f, 0.5f, v));         // no limit by default
  EXPECT_FALSE(sample_disparity_bilinear(d, 1.5f, 0.5f, v, 1.5f));  // spread 2 > 1.5
  EXPECT_TRUE(sample_disparity_bilinear(d, 1.5f, 0.5f, v, 2.0f));
  EXPECT_TRUE(sample_disparity_bilinear(d, 1.0f, 0.5f, v, 0.5f));   // (2, 1) unused
  EXPECT_FLOAT_EQ(v, 5.0f);
}

TEST(SampleFlow, BilinearAndInvalid) {
  cv::Mat f(3, 4, CV_32FC2);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) f.at<cv::Vec2f>(y, x) = cv::Vec2f(x * 2.0f, -y * 3.0f);
  cv::Vec2f v;
  ASSERT_TRUE(sample_flow_bilinear(f, 1.25f, 0.5f, v));
  EXPECT_FLOAT_EQ(v[0], 2.5f);
  EXPECT_FLOAT_EQ(v[1], -1.5f);
  f.at<cv::Vec2f>(1, 2)[1] = NAN;
  EXPECT_FALSE(sample_flow_bilinear(f, 1.5f, 0.5f, v));
  EXPECT_TRUE(sample_flow_bilinear(f, 1.0f, 0.5f, v));
  EXPECT_FALSE(sample_flow_bilinear(f, 3.01f, 0.0f, v));
}

// ---------------------------------------------------------------------------------------------
// 3D velocity and the envelope test

core::Camera odd_camera() {
  core::Camera c;
  c.width = 151;
  c.height = 117;
  c.focal_px = 200.0;
  c.baseline_m = 0.1;
  c.cx = 74.3;
  c.cy = 57.8;
  return c;
}

TEST(PointVelocity, RecoversAKnownMotion) {
  const core::Camera cam = odd_camera();
  const double dt = 0.1;
  const cv::Point3d before(0.4, -0.2, 5.0);
  const cv::Vec3d truth(-0.3, 0.1, -2.0);
  const cv::Point3d now = before + cv::Point3d(truth * dt);
  // Pixels and disparities exactly as a camera would see them (then rounded to float).
  const cv::Point2d p = cam.project(now), q = cam.project(before);
  const float d_cur = static_cast<float>(cam.focal_px * cam.baseline_m / now.z);
  const float d_prev = static_cast<float>(cam.focal_px * cam.baseline_m / before.z);
  cv::Vec3d v;
  cv::Point3d pos;
  ASSERT_TRUE(point_velocity(cv::Point2f(p), d_cur, cv::Point2f(q), d_prev, cam, dt, v, pos));
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(v[i], truth[i], 2e-4) << i;  // float pixels, /dt
  EXPECT_NEAR(pos.x, now.x, 1e-5);
  EXPECT_NEAR(pos.y, now.y, 1e-5);
  EXPECT_NEAR(pos.z, now.z, 1e-5);
  EXPECT_FALSE(point_velocity(cv::Point2f(p), 0.0f, cv::Point2f(q), d_prev, cam, dt, v, pos));
  EXPECT_FALSE(point_velocity(cv::Point2f(p), d_cur, cv::Point2f(q), -1.0f, cam, dt, v, pos));
  EXPECT_FALSE(point_velocity(cv::Point2f(p), d_cur, cv::Point2f(q), d_prev, cam, 0.0, v, pos));
}

// Default envelope: |X| <= 0.5, -1 <= Y <= 1, z_contact 0.5 m, horizon 3 s.
TEST(HeadsIntoEnvelope, HandComputedCases) {
  const core::Envelope e;
  const double v_min = 0.3;
  double t = -1;
  // Straight in: t_c = (4.5 - 0.5) / 2 = 2 s at (0.2, 0.3).
  EXPECT_TRUE(heads_into_envelope({0.2, 0.3, 4.5}, {0, 0, -2}, e, v_min, t));
  EXPECT_DOUBLE_EQ(t, 2.0);
  // From the side into it: t_c = 3 / 1.5 = 2 s, X(2) = 1.0 - 0.8 = 0.2.
  EXPECT_TRUE(heads_into_envelope({1.0, 0.0, 3.5}, {-0.4, 0, -1.5}, e, v_min, t));
  EXPECT_DOUBLE_EQ(t, 2.0);
  t = -1;
  // Passing beside: X stays 1.0; crossing through: X(2) = -0.2 + 1.0 = 0.8.
  EXPECT_FALSE(heads_into_envelope({1.0, 0.0, 3.5}, {0, 0, -1.5}, e, v_min, t));
  EXPECT_FALSE(heads_into_envelope({-0.2, 0.0, 3.5}, {0.5, 0, -1.5}, e, v_min, t));
  // Ground below the envelope (ego motion towards it): Y = 1.3 > y_bottom.
  EXPECT_FALSE(heads_into_envelope({0.0, 1.3, 2.5}, {0, 0, -1}, e, v_min, t));
  // Overhead: Y = -1.2 < y_top.
  EXPECT_FALSE(heads_into_envelope({0.0, -1.2, 2.5}, {0, 0, -1}, e, v_min, t));
  // Receding.
  EXPECT_FALSE(heads_into_envelope({0.0, 0.0, 2.5}, {0, 0, 1}, e, v_min, t));
  // Slow: |V_z| = 0.2 < v_min although t_c = 0.3 / 0.2 = 1.5 s is within the horizon.
  EXPECT_FALSE(heads_into_envelope({0.0, 0.0, 0.8}, {0, 0, -0.2}, e, v_min, t));
  EXPECT_TRUE(heads_into_envelope({0.0, 0.0, 0.8}, {0, 0, -0.2}, e, 0.1, t));
  EXPECT_DOUBLE_EQ(t, 1.5);
  // Beyond the horizon: t_c = 8 / 2 = 4 s > 3 s; a 5 s horizon catches it.
  EXPECT_FALSE(heads_into_envelope({0.0, 0.0, 8.5}, {0, 0, -2}, e, v_min, t));
  core::Envelope longer = e;
  longer.horizon_s = 5.0;
  EXPECT_TRUE(heads_into_envelope({0.0, 0.0, 8.5}, {0, 0, -2}, longer, v_min, t));
  EXPECT_DOUBLE_EQ(t, 4.0);
  // Already closer than z_contact: t_c <= 0 is not a future contact.
  EXPECT_FALSE(heads_into_envelope({0.0, 0.0, 0.4}, {0, 0, -2}, e, v_min, t));
}

TEST(HeadsIntoEnvelopeTurning, AStaticPointMeetsThePlatformOnlyOnItsArc) {
  // A car at 10 m/s turning right at 20 deg/s drives a circle of radius R about (R, 0, 0).
  core::Envelope e;
  e.half_width_m = 1.0;
  e.y_top_m = -0.4;
  e.y_bottom_m = 1.1;
  e.z_contact_m = 2.0;
  e.horizon_s = 3.0;
  const double w = 20.0 * CV_PI / 180.0, radius = 10.0 / w;
  const cv::Vec3d still(0, 0, -10.0);  // a static point's velocity without the rotation
  double t = -1.0;
  // On the arc 45 deg on (22.5 m of arc): met after the arc to the contact plane.
  const double a = 45.0 * CV_PI / 180.0;
  const cv::Point3d on_arc(radius * (1 - std::cos(a)), 0.5, radius * std::sin(a));
  ASSERT_TRUE(heads_into_envelope_turning(on_arc, still, w, e, 0.1, t));
  // Contact when the point's camera depth, R sin(arc angle left), is z_contact.
  const double left = std::asin(e.z_contact_m / radius);
  EXPECT_NEAR(t, (a - left) * radius / 10.0, 1e-6);
  // The straight line would meet it nowhere (it is 8.4 m to the right)...
  EXPECT_FALSE(heads_into_envelope(on_arc, still, e, 0.1, t));
  // ... and a point straight ahead, which the straight line meets, is passed by.
  const cv::Point3d ahead(0.0, 0.5, radius * std::sin(a));
  EXPECT_TRUE(heads_into_envelope(ahead, still, e, 0.1, t));
  EXPECT_FALSE(heads_into_envelope_turning(ahead, still, w, e, 0.1, t));
  // Mirrored: a left turn meets the mirrored point after the same time.
  double t_left = -1.0;
  ASSERT_TRUE(heads_into_envelope_turning({-on_arc.x, on_arc.y, on_arc.z}, still, -w, e, 0.1,
                                          t_left));
  EXPECT_NEAR(t_left, (a - left) * radius / 10.0, 1e-6);
  // Out of the horizon, out of the band, receding or too slow: no.
  const double b = 120.0 * CV_PI / 180.0;
  EXPECT_FALSE(heads_into_envelope_turning({radius * (1 - std::cos(b)), 0.5, radius * std::sin(b)},
                                           still, w, e, 0.1, t));
  EXPECT_FALSE(heads_into_envelope_turning({on_arc.x, -2.0, on_arc.z}, still, w, e, 0.1, t));
  EXPECT_FALSE(heads_into_envelope_turning(on_arc, -still, w, e, 0.1, t));
  EXPECT_FALSE(heads_into_envelope_turning(on_arc, {0, 0, -0.05}, w, e, 0.1, t));
}

TEST(HeadsIntoEnvelopeTurning, ASlowTurnAgreesWithTheStraightLine) {
  // 0.001 deg/s: the arc leaves the line by millimetres over the horizon; verdicts agree except
  // within them of the envelope's edges, and TTCs agree.
  core::Envelope e;
  const double w = 0.001 * CV_PI / 180.0;
  cv::RNG rng(5);
  int both = 0, compared = 0;
  for (int i = 0; i < 20000; ++i) {
    const cv::Point3d P(rng.uniform(-3.0, 3.0), rng.uniform(-1.0, 1.0), rng.uniform(0.2, 15.0));
    const cv::Vec3d V(rng.uniform(-1.0, 1.0), rng.uniform(-0.3, 0.3), rng.uniform(-6.0, 1.0));
    double t_line = -1.0, t_arc = -1.0;
    const bool line = heads_into_envelope(P, V, e, 0.1, t_line);
    const bool arc = heads_into_envelope_turning(P, V, w, e, 0.1, t_arc);
    if (line != arc) {
      // Only where the line passes within 5 mm of the envelope's side or horizon.
      const double t_c = (P.z - e.z_contact_m) / -V[2];
      const double x = P.x + V[0] * t_c;
      EXPECT_TRUE(std::abs(std::abs(x) - e.half_width_m) < 5e-3 ||
                  std::abs(t_c - e.horizon_s) < 1e-3)
          << P << " " << V;
      continue;
    }
    ++compared;
    if (line) {
      ++both;
      EXPECT_NEAR(t_arc, t_line, 1e-3 * t_line) << P << " " << V;
    }
  }
  EXPECT_GT(compared, 19900);
  EXPECT_GT(both, 500);  // the sample does reach the envelope
}

TEST(SceneFlowParams, Validate) {
  EXPECT_TRUE(validate(SceneFlowParams{}).empty());
  SceneFlowParams p;
  p.gaps = {1, 0};
  p.v_min_mps = -1;
  const auto problems = validate(p);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_NE(problems[0].find("scene_flow.gaps=0"), std::string::npos);
  EXPECT_NE(problems[1].find("scene_flow.v_min_mps=-1"), std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// Labelling on synthetic maps

constexpr double kDt = 1.0 / 30.0;

/// The thesis' test alone: no depth-edge margin, no band, far range, any gap flags. The filters
/// added for real matchers have their own tests below.
SceneFlowParams plain() {
  SceneFlowParams p;
  p.edge_margin_px = 0;
  p.use_envelope_band = false;
  p.longest_gap_decides = false;
  p.fit_velocity = false;  // the gaps' own semantics; the fit has tests of its own
  p.z_max_m = 50.0;
  p.chain_stride = 1;  // every candidate followed; the stride has its own test
  return p;
}

/// Background: a wall at 20 m (d = 1 px for f B = 20), flow zero.
struct Maps {
  cv::Mat cur, prev, flow;
};
Maps wall(const core::Camera& cam) {
  Maps m;
  m.cur = cv::Mat(cam.height, cam.width, CV_32F, cv::Scalar(1.0f));
  m.prev = m.cur.clone();
  m.flow = cv::Mat(cam.height, cam.width, CV_32FC2, cv::Scalar(0, 0));
  return m;
}

TEST(LabelStereoFlow, HeadOnPatchIsDangerous) {
  const core::Camera cam = odd_camera();  // f B = 20
  Maps m = wall(cam);
  const cv::Rect patch(60, 45, 31, 27);
  // 2.0 m -> 1.9 m in one frame: V_z = -3 m/s, straight along the rays (flow zero).
  m.prev(patch).setTo(20.0 / 2.0);
  m.cur(patch).setTo(20.0 / 1.9);
  cv::Mat danger, ttc, vel;
  label_stereo_flow(m.cur, m.prev, m.flow, cam, {}, plain(), kDt, danger, ttc, vel);
  ASSERT_EQ(danger.type(), CV_8UC1);
  ASSERT_EQ(ttc.type(), CV_32FC1);
  ASSERT_EQ(vel.type(), CV_32FC3);
  EXPECT_EQ(cv::countNonZero(danger(patch)), patch.area());
  EXPECT_EQ(cv::countNonZero(danger), patch.area());
  const double z_now = 20.0 / static_cast<float>(20.0 / 1.9);
  const double z_before = 20.0 / static_cast<float>(20.0 / 2.0);
  const double vz = (z_now - z_before) / kDt;
  EXPECT_NEAR(vz, -3.0, 1e-3);
  const cv::Point c(75, 58);
  EXPECT_NEAR(ttc.at<float>(c), (z_now - 0.5) / -vz, 1e-4);
  EXPECT_NEAR(vel.at<cv::Vec3f>(c)[2], vz, 1e-3);
  // The wall is static: velocity known and zero, TTC NaN.
  EXPECT_TRUE(std::isnan(ttc.at<float>(5, 5)));
  EXPECT_NEAR(cv::norm(vel.at<cv::Vec3f>(5, 5)), 0.0, 1e-6);
}

// chain_stride: candidates nearer than chain_stride_z_m are followed on every second row and
// column only, those sqrt(2) nearer on every fourth column, those nearer than half of it on every
// fourth row and column, far ones all; pooling then gives the unfollowed ones their surface's
// velocity, and the pooled mask is the one of following every candidate. Without pooling the
// stride is off.
TEST(LabelStereoFlow, ChainStrideFollowsFewerNearPixelsTheNearerAndPoolingFillsTheRest) {
  const core::Camera cam = odd_camera();  // f B = 20
  Maps m = wall(cam);
  const cv::Rect nearest(60, 45, 31, 27), near(100, 80, 31, 27), far_patch(10, 10, 21, 15);
  const cv::Rect between(10, 80, 31, 27);
  m.prev(nearest).setTo(20.0 / 2.0);  // 2.0 m -> 1.9 m: under half the stride zone's 4 m
  m.cur(nearest).setTo(20.0 / 1.9);
  m.prev(between).setTo(20.0 / 2.6);  // 2.6 m -> 2.5 m: under 4 m / sqrt(2), over 2 m
  m.cur(between).setTo(20.0 / 2.5);
  m.prev(near).setTo(20.0 / 3.1);  // 3.1 m -> 3.0 m: in the stride zone
  m.cur(near).setTo(20.0 / 3.0);
  m.prev(far_patch).setTo(20.0 / 6.2);  // 6.2 m -> 6.1 m: far, followed everywhere
  m.cur(far_patch).setTo(20.0 / 6.1);
  SceneFlowParams strided = plain();
  strided.chain_stride = 2;
  strided.chain_stride_z_m = 4.0;
  strided.min_delta_d_px = 0.0;  // one frame's motion is the whole span here
  SceneFlowParams every = strided;
  every.chain_stride = 1;
  cv::Mat d2, t2, v2, d1, t1, v1;
  label_stereo_flow(m.cur, m.prev, m.flow, cam, {}, strided, kDt, d2, t2, v2);
  label_stereo_flow(m.cur, m.prev, m.flow, cam, {}, every, kDt, d1, t1, v1);
  struct Strided {
    cv::Rect patch;
    int columns, rows;
  };
  for (const Strided& s : {Strided{nearest, 4, 4}, Strided{between, 4, 2}, Strided{near, 2, 2}})
    for (int y = s.patch.y; y < s.patch.br().y; ++y)
      for (int x = s.patch.x; x < s.patch.br().x; ++x) {
        const bool followed = y % s.rows == 0 && x % s.columns == 0;
        EXPECT_EQ(std::isnan(v2.at<cv::Vec3f>(y, x)[2]), !followed) << x << "," << y;
        if (s.rows == 4) {
          EXPECT_EQ(d2.at<uint8_t>(y, x) != 0, followed) << x << "," << y;
        }
      }
  EXPECT_EQ(cv::countNonZero(d2(far_patch) != d1(far_patch)), 0);
  EXPECT_EQ(cv::countNonZero(d1(nearest)), nearest.area());
  // Pooled, the strided labelling marks what following every candidate marks.
  // Depth edges one pixel outside each patch part it from the wall.
  cv::Mat edges = cv::Mat::zeros(m.cur.size(), CV_8U);
  for (const cv::Rect& r : {nearest, between, near, far_patch})
    cv::rectangle(edges, r - cv::Point(1, 1) + cv::Size(2, 2), 255, 1);
  pool_surface_motion(m.cur, cam, {}, strided, kDt, edges, d2, t2, v2);
  pool_surface_motion(m.cur, cam, {}, every, kDt, edges, d1, t1, v1);
  EXPECT_EQ(cv::countNonZero(d2 != d1), 0);
  EXPECT_EQ(cv::countNonZero(d2(nearest)), nearest.area());
  // Without pooling nobody would fill the gaps: the stride is off.
  SceneFlowParams unpooled = strided;
  unpooled.pool_surface_motion = false;
  cv::Mat d0, t0, v0;
  label_stereo_flow(m.cur, m.prev, m.flow, cam, {}, unpooled, kDt, d0, t0, v0);
  EXPECT_EQ(cv::countNonZero(d0(nearest)), nearest.area());
}

// The point of the mode: a patch moving sideways at constant depth changes the disparity at fixed
// pixels along its edges (Stereo mode flags them) but its 3D motion does not approach.
TEST(LabelStereoFlow, CrossingPatchIsSafeEvenAtItsEdges) {
  const core::Camera cam = odd_camera();
  Maps m = wall(cam);
  const int shift = 6;
  const cv::Rect before(30, 40, 30, 31), now = before + cv::Point(shift, 0);
  m.prev(before).setTo(10.0);  // 2 m
  m.cur(now).setTo(10.0);
  m.flow(now).setTo(cv::Scalar(-shift, 0));
  const cv::Point leading_edge(now.br().x - 2, now.y + 10);
  ASSERT_GE(m.cur.at<float>(leading_edge) - m.prev.at<float>(leading_edge), 0.5f);
  cv::Mat danger, ttc, vel;
  label_stereo_flow(m.cur, m.prev, m.flow, cam, {}, plain(), kDt, danger, ttc, vel);
  EXPECT_EQ(cv::countNonZero(danger), 0);
  const cv::Vec3f v = vel.at<cv::Vec3f>(leading_edge);
  EXPECT_NEAR(v[0], shift * 2.0 / cam.focal_px / kDt, 1e-3);  // 1.8 m/s sideways
  EXPECT_NEAR(v[2], 0.0, 1e-4);
}

TEST(LabelStereoFlow, UnknownWhereTheFlowLeavesTheImage) {
  const core::Camera cam = odd_camera();
  Maps m = wall(cam);
  m.flow.setTo(cv::Scalar(-3, 0));
  m.cur.at<float>(10, 20) = -1.0f;
  cv::Mat danger, ttc, vel;
  label_stereo_flow(m.cur, m.prev, m.flow, cam, {}, plain(), kDt, danger, ttc, vel);
  EXPECT_TRUE(std::isnan(vel.at<cv::Vec3f>(10, 2)[0]));   // q.x = -1
  EXPECT_FALSE(std::isnan(vel.at<cv::Vec3f>(10, 3)[0]));  // q.x = 0
  EXPECT_TRUE(std::isnan(vel.at<cv::Vec3f>(10, 20)[2]));  // D_i invalid
  EXPECT_THROW(label_stereo_flow(m.cur, m.prev(cv::Rect(0, 0, 10, 10)), m.flow, cam, {}, plain(),
                                 kDt, danger, ttc, vel),
               core::InputError);
}

// ---------------------------------------------------------------------------------------------
// Naive reference: written from DESIGN 3.2 with at<>() and double arithmetic, sharing nothing
// with the implementation.

bool naive_sample(const cv::Mat& m, int channel, double x, double y, double& out,
                  double max_step = INFINITY) {
  if (!(x >= 0 && y >= 0 && x <= m.cols - 1 && y <= m.rows - 1)) return false;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const double fx = x - x0, fy = y - y0;
  double sum = 0, lo = INFINITY, hi = -INFINITY;
  for (int dy = 0; dy < 2; ++dy)
    for (int dx = 0; dx < 2; ++dx) {
      const double w = (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy);
      if (w == 0) continue;
      const float v = m.channels() == 1 ? m.at<float>(y0 + dy, x0 + dx)
                                        : m.at<cv::Vec2f>(y0 + dy, x0 + dx)[channel];
      if (m.channels() == 1 ? !(v >= 0) : !std::isfinite(v)) return false;
      sum += w * v;
      lo = std::min<double>(lo, v);
      hi = std::max<double>(hi, v);
    }
  if (hi - lo > max_step) return false;
  out = sum;
  return true;
}

struct NaiveOut {
  bool danger = false;
  double ttc = NAN;
  cv::Vec3d vel{NAN, NAN, NAN};
};

/// The envelope test of DESIGN 3.2 for the point P moving at V; tc = time to contact when true.
bool naive_heads_in(const cv::Vec3d& P, const cv::Vec3d& V, const core::Envelope& e,
                    const SceneFlowParams& p, double& tc) {
  if (!(V[2] <= -p.v_min_mps)) return false;
  tc = (P[2] - e.z_contact_m) / -V[2];
  const double X = P[0] + V[0] * tc, Y = P[1] + V[1] * tc;
  return tc > 0 && tc <= e.horizon_s && std::abs(X) <= e.half_width_m && Y >= e.y_top_m &&
         Y <= e.y_bottom_m;
}

/// With fit_velocity: the chain followed one flow at a time up to the longest gap (or the
/// history), every frame's position sampled, a least-squares line fitted with weights (d_m / d)^4
/// by the textbook formulas, then the noise gate on the fitted motion over the oldest sample's
/// span.
NaiveOut naive_fit_pixel(int x, int y, const cv::Mat& cur, const std::vector<cv::Mat>& disps,
                         const std::vector<cv::Mat>& flows, const std::vector<int>& gaps,
                         const core::Camera& c, const core::Envelope& e, const SceneFlowParams& p) {
  NaiveOut out;
  const double d = cur.at<float>(y, x);
  const double fb = c.focal_px * c.baseline_m;
  if (!(d > 0) || fb / d > p.z_max_m) return out;
  auto point = [&c, fb](double px, double py, double disp) {
    const double zz = fb / disp;
    return cv::Vec3d((px - c.cx) * zz / c.focal_px, (py - c.cy) * zz / c.focal_px, zz);
  };
  std::vector<double> ts{0.0}, ws{1.0};
  std::vector<cv::Vec3d> ps{point(x, y, d)};
  const int longest =
      std::min(*std::max_element(gaps.begin(), gaps.end()), static_cast<int>(disps.size()));
  double qx = x, qy = y;
  for (int m = 0; m < longest; ++m) {
    double u, v;
    if (!naive_sample(flows[m], 0, qx, qy, u) || !naive_sample(flows[m], 1, qx, qy, v)) break;
    qx = static_cast<float>(static_cast<float>(qx) + static_cast<float>(u));
    qy = static_cast<float>(static_cast<float>(qy) + static_cast<float>(v));
    double dp;
    if (!naive_sample(disps[m], 0, qx, qy, dp, p.max_disparity_step_px) || !(dp > 0)) continue;
    ts.push_back(-(m + 1) * kDt);
    ws.push_back(std::pow(dp / d, 4));
    ps.push_back(point(qx, qy, dp));
  }
  if (ts.size() < 2) return out;
  // The weighted least-squares line through the samples but `skip` (-1: none): mean time,
  // mean position, slope.
  auto line = [&](int skip, double& tm, cv::Vec3d& pm, cv::Vec3d& slope) {
    double sw = 0;
    tm = 0;
    pm = cv::Vec3d(0, 0, 0);
    for (size_t i = 0; i < ts.size(); ++i)
      if (static_cast<int>(i) != skip) sw += ws[i], tm += ws[i] * ts[i], pm += ws[i] * ps[i];
    tm /= sw;
    pm /= sw;
    double stt = 0;
    cv::Vec3d stp(0, 0, 0);
    for (size_t i = 0; i < ts.size(); ++i)
      if (static_cast<int>(i) != skip) {
        stt += ws[i] * (ts[i] - tm) * (ts[i] - tm);
        stp += ws[i] * (ts[i] - tm) * (ps[i] - pm);
      }
    slope = stp / stt;
    return stt > 1e-12;
  };
  // An outlier: a sample's disparity off the line through the others by more than both bounds.
  if (p.chain_outlier_px > 0 && ts.size() >= 3)
    for (size_t j = 0; j < ts.size(); ++j) {
      double tm;
      cv::Vec3d pm, slope;
      if (!line(static_cast<int>(j), tm, pm, slope)) continue;
      const double z_line = pm[2] + slope[2] * (ts[j] - tm);
      const double dj = fb / ps[j][2];
      if (!(z_line > 0) ||
          std::abs(dj - fb / z_line) > std::max(p.chain_outlier_px, p.chain_outlier_fraction * dj))
        return out;  // velocity unknown
    }
  double tm;
  cv::Vec3d pm, V;
  line(-1, tm, pm, V);
  out.vel = V;
  const cv::Vec3d& P = ps[0];
  const double z_before = P[2] - V[2] * -ts.back();
  double tc = 0;
  if (z_before > 0 && d - fb / z_before >= p.min_delta_d_px && cv::norm(V) <= p.max_speed_mps &&
      naive_heads_in(P, V, e, p, tc)) {
    out.danger = true;
    out.ttc = tc;
  }
  return out;
}

NaiveOut naive_pixel(int x, int y, const cv::Mat& cur, const std::vector<cv::Mat>& disps,
                     const std::vector<cv::Mat>& flows, const std::vector<int>& gaps,
                     const core::Camera& c, const core::Envelope& e, const SceneFlowParams& p) {
  if (p.fit_velocity) return naive_fit_pixel(x, y, cur, disps, flows, gaps, c, e, p);
  NaiveOut out;
  const double d = cur.at<float>(y, x);
  if (!(d > 0)) return out;
  const double z = c.focal_px * c.baseline_m / d;
  if (z > p.z_max_m) return out;  // not a candidate: velocity unknown
  const cv::Vec3d P((x - c.cx) * z / c.focal_px, (y - c.cy) * z / c.focal_px, z);
  int best_valid_gap = 0;
  std::vector<int> ascending = gaps;
  std::sort(ascending.begin(), ascending.end());
  for (int k : ascending) {
    if (k > static_cast<int>(disps.size())) continue;
    double qx = x, qy = y;
    bool ok = true;
    for (int m = 0; m < k && ok; ++m) {
      double u, v;
      ok = naive_sample(flows[m], 0, qx, qy, u) && naive_sample(flows[m], 1, qx, qy, v);
      // Positions are float in the implementation; keep the reference on the same grid.
      qx = static_cast<float>(static_cast<float>(qx) + static_cast<float>(u));
      qy = static_cast<float>(static_cast<float>(qy) + static_cast<float>(v));
    }
    double dp;
    if (!ok || !naive_sample(disps[k - 1], 0, qx, qy, dp, p.max_disparity_step_px) || !(dp > 0))
      continue;
    const double zp = c.focal_px * c.baseline_m / dp;
    const cv::Vec3d Pp((qx - c.cx) * zp / c.focal_px, (qy - c.cy) * zp / c.focal_px, zp);
    const cv::Vec3d V = (P - Pp) / (k * kDt);
    bool flag = z <= p.z_max_m && d - dp >= p.min_delta_d_px && cv::norm(V) <= p.max_speed_mps &&
                V[2] <= -p.v_min_mps;
    double tc = 0;
    if (flag) {
      tc = (z - e.z_contact_m) / -V[2];
      const double X = P[0] + V[0] * tc, Y = P[1] + V[1] * tc;
      flag = tc > 0 && tc <= e.horizon_s && std::abs(X) <= e.half_width_m && Y >= e.y_top_m &&
             Y <= e.y_bottom_m;
    }
    if (p.longest_gap_decides) {  // ascending: the last known gap wins
      out.danger = flag;
      out.ttc = flag ? tc : NAN;
      out.vel = V;
      continue;
    }
    if (flag && (!out.danger || tc < out.ttc)) {
      out.ttc = tc;
      out.vel = V;
    }
    out.danger = out.danger || flag;
    if (!out.danger && k > best_valid_gap) {
      out.vel = V;
      best_valid_gap = k;
    }
  }
  return out;
}

/// Smooth random disparity in [lo, hi] with ~8% invalid pixels, as a ROI of a larger matrix so
/// that rows are not contiguous.
cv::Mat random_disparity(cv::Size size, double lo, double hi, cv::RNG& rng) {
  cv::Mat big(size.height + 6, size.width + 9, CV_32F);
  rng.fill(big, cv::RNG::UNIFORM, 0.0, 1.0);
  cv::GaussianBlur(big, big, cv::Size(0, 0), 3.0);
  cv::normalize(big, big, lo, hi, cv::NORM_MINMAX);
  cv::Mat roi = big(cv::Rect(4, 3, size.width, size.height));
  for (int i = 0; i < size.area() / 12; ++i)
    roi.at<float>(rng.uniform(0, size.height), rng.uniform(0, size.width)) = -1.0f;
  return roi;
}

cv::Mat random_flow(cv::Size size, double amplitude, cv::RNG& rng) {
  cv::Mat big(size.height + 4, size.width + 5, CV_32FC2);
  rng.fill(big, cv::RNG::UNIFORM, -amplitude, amplitude);
  cv::GaussianBlur(big, big, cv::Size(0, 0), 2.0);
  return big(cv::Rect(2, 1, size.width, size.height));
}

/// The small odd camera and wide envelope of the random-map comparisons.
core::Camera random_map_camera() {
  core::Camera cam = odd_camera();
  cam.width = 63;
  cam.height = 49;
  cam.cx = 31.2;
  cam.cy = 24.6;
  return cam;
}

core::Envelope random_map_envelope() {
  core::Envelope env;
  env.half_width_m = 1.5;
  env.y_top_m = -1.5;
  env.y_bottom_m = 1.5;
  return env;
}

void compare_with_naive(const std::vector<int>& gaps, int history, uint64_t seed,
                        bool longest = false, bool fit = false) {
  const core::Camera cam = random_map_camera();
  const cv::Size size(cam.width, cam.height);
  const core::Envelope env = random_map_envelope();
  SceneFlowParams p = plain();
  p.longest_gap_decides = longest;
  p.fit_velocity = fit;
  p.z_max_m = 2.0;  // some of the random points (0.67 .. 2.5 m) lie beyond
  p.gaps = gaps;
  p.min_delta_d_px = 0.2;
  p.max_disparity_step_px = 1.5;
  cv::RNG rng(seed);
  const cv::Mat cur = random_disparity(size, 8.0, 30.0, rng);
  std::vector<cv::Mat> disps, flows;
  std::vector<const cv::Mat*> dp, fp;
  for (int j = 0; j < history; ++j) {
    disps.push_back(random_disparity(size, 6.0, 28.0, rng));
    flows.push_back(random_flow(size, 6.0, rng));
  }
  for (int j = 0; j < history; ++j) {
    dp.push_back(&disps[j]);
    fp.push_back(&flows[j]);
  }
  cv::Mat danger, ttc, vel;
  if (gaps.size() == 1 && gaps[0] == 1 && history == 1)
    label_stereo_flow(cur, disps[0], flows[0], cam, env, p, kDt, danger, ttc, vel);
  else
    label_stereo_flow_window(cur, dp, fp, cam, env, p, kDt, danger, ttc, vel);
  int flagged = 0, known = 0;
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      const NaiveOut r = naive_pixel(x, y, cur, disps, flows, gaps, cam, env, p);
      ASSERT_EQ(danger.at<uint8_t>(y, x), r.danger ? 255 : 0) << x << "," << y;
      flagged += r.danger;
      if (r.danger) {
        EXPECT_NEAR(ttc.at<float>(y, x), r.ttc, 1e-4 * (1 + r.ttc)) << x << "," << y;
      } else {
        EXPECT_TRUE(std::isnan(ttc.at<float>(y, x))) << x << "," << y;
      }
      const cv::Vec3f v = vel.at<cv::Vec3f>(y, x);
      if (std::isnan(r.vel[0])) {
        EXPECT_TRUE(std::isnan(v[0])) << x << "," << y;
        continue;
      }
      ++known;
      for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(v[i], r.vel[i], 1e-3 * (1 + std::abs(r.vel[i]))) << x << "," << y;
    }
  // The random maps must exercise both outcomes.
  EXPECT_GT(flagged, 30);
  EXPECT_LT(flagged, size.area() * 4 / 5);
  EXPECT_GT(known, size.area() / 3);
}

TEST(LabelStereoFlow, MatchesNaiveReferenceOnRandomMaps) {
  for (uint64_t seed : {1u, 2u, 3u}) compare_with_naive({1}, 1, seed);
}

TEST(LabelStereoFlowWindow, MatchesNaiveReferenceOnRandomMaps) {
  for (uint64_t seed : {4u, 5u}) compare_with_naive({3, 1, 2}, 3, seed);
  compare_with_naive({1, 2, 5}, 3, 6);  // gap 5 lacks history and is skipped
}

// The pipeline runs the labelling in row bands on the farm: bands stitched must equal the whole
// image bit for bit (the whole-image call is itself checked against the naive reference above).
TEST(LabelStereoFlowRows, BandsStitchedEqualTheWholeImage) {
  const core::Camera cam = random_map_camera();
  const cv::Size size(cam.width, cam.height);
  const core::Envelope env = random_map_envelope();
  // 0: any gap flags, 1: the longest gap decides, 2: the velocity fit.
  for (int longest : {0, 1, 2}) {
    SceneFlowParams p = plain();
    p.longest_gap_decides = longest == 1;
    p.fit_velocity = longest == 2;
    p.z_max_m = 2.0;
    p.gaps = {1, 2, 4};
    p.min_delta_d_px = 0.2;
    p.max_disparity_step_px = 1.5;
    p.edge_margin_px = 1;
    cv::RNG rng(21 + longest);
    const cv::Mat cur = random_disparity(size, 8.0, 30.0, rng);
    std::vector<cv::Mat> disps, flows;
    std::vector<const cv::Mat*> dp, fp;
    for (int j = 0; j < 4; ++j) {
      disps.push_back(random_disparity(size, 6.0, 28.0, rng));
      flows.push_back(random_flow(size, 6.0, rng));
    }
    for (int j = 0; j < 4; ++j) {
      dp.push_back(&disps[j]);
      fp.push_back(&flows[j]);
    }
    cv::Mat danger, ttc, vel;
    label_stereo_flow_window(cur, dp, fp, cam, env, p, kDt, danger, ttc, vel);
    ASSERT_GT(cv::countNonZero(danger), 0);
    cv::Mat edges;
    mark_depth_edges(cur, p.edge_margin_px, p.edge_step_px, edges);
    std::vector<GapSource> gaps;
    for (int k : longest == 2 ? std::vector<int>{4, 1, 3, 2} : std::vector<int>{4, 1, 2})
      gaps.push_back({k, dp[k - 1], nullptr, k * kDt});
    cv::Mat bd, bt, bv;
    allocate_stereo_flow_outputs(size, bd, bt, bv);
    for (const cv::Range r : {cv::Range(30, 49), cv::Range(0, 7), cv::Range(7, 30)})
      label_stereo_flow_rows(cur, edges, fp, gaps, cam, env, p, bd, bt, bv, r);
    EXPECT_EQ(cv::countNonZero(danger != bd), 0) << "longest " << longest;
    // NaN != NaN: compare the bytes.
    EXPECT_EQ(std::memcmp(ttc.data, bt.data, ttc.total() * ttc.elemSize()), 0);
    EXPECT_EQ(std::memcmp(vel.data, bv.data, vel.total() * vel.elemSize()), 0);
  }
}

TEST(LabelStereoFlowWindow, LongestGapDecidesMatchesNaiveReference) {
  for (uint64_t seed : {7u, 8u}) compare_with_naive({3, 1, 2}, 3, seed, true);
}

TEST(LabelStereoFlowWindow, VelocityFitMatchesNaiveReference) {
  for (uint64_t seed : {9u, 10u}) compare_with_naive({3}, 3, seed, false, true);
  compare_with_naive({1, 5}, 3, 11, false, true);  // the history ends the chain before gap 5
}

TEST(SampledGaps, TheFitSamplesEveryFrameUpToTheLongestGap) {
  SceneFlowParams p;
  p.gaps = {4, 1};
  p.fit_velocity = false;
  EXPECT_EQ(sampled_gaps(p), (std::vector<int>{4, 1}));
  p.fit_velocity = true;
  EXPECT_EQ(sampled_gaps(p), (std::vector<int>{1, 2, 3, 4}));
}

// A fronto-parallel 0.6 m square on the optical axis approaching at 3 m/s from 9 m: it reaches
// z_contact in 8.5 / 3 = 2.83 s, within the horizon, but its disparity grows by only 0.07 px per
// frame, below min_delta_d_px = 0.5 (and below stereo noise). Over 10 frames it grows by 0.67 px.
class FarApproach : public ::testing::Test {
 protected:
  static constexpr int kFrames = 11;  // D_i .. D_{i-10}
  void SetUp() override {
    cam_.width = 201;
    cam_.height = 151;
    cam_.focal_px = 500.0;
    cam_.baseline_m = 0.12;  // f B = 60
    cam_.cx = 100.0;
    cam_.cy = 75.0;
    for (int j = 0; j < kFrames; ++j) {
      const double z = 9.0 + 3.0 * kDt * j;  // frame i - j
      cv::Mat d(cam_.height, cam_.width, CV_32F, cv::Scalar(2.0f));  // wall at 30 m
      cv::rectangle(d, square(z), cv::Scalar(60.0 / z), cv::FILLED);
      disps_.push_back(d);
    }
    // Flow of frame i - j back to i - j - 1: the square shrinks about the principal point.
    for (int j = 0; j + 1 < kFrames; ++j) {
      const double scale = (9.0 + 3.0 * kDt * j) / (9.0 + 3.0 * kDt * (j + 1));
      cv::Mat f(cam_.height, cam_.width, CV_32FC2, cv::Scalar(0, 0));
      const cv::Rect r = square(9.0 + 3.0 * kDt * j);
      for (int y = r.y; y < r.br().y; ++y)
        for (int x = r.x; x < r.br().x; ++x)
          f.at<cv::Vec2f>(y, x) = cv::Vec2f(static_cast<float>((x - cam_.cx) * (scale - 1)),
                                            static_cast<float>((y - cam_.cy) * (scale - 1)));
      flows_.push_back(f);
    }
  }
  cv::Rect square(double z) const {
    const int half = static_cast<int>(cam_.focal_px * 0.3 / z);
    return {static_cast<int>(cam_.cx) - half, static_cast<int>(cam_.cy) - half, 2 * half + 1,
            2 * half + 1};
  }
  void label(const std::vector<int>& gaps, int history, bool fit = false) {
    std::vector<const cv::Mat*> d, f;
    for (int j = 0; j < history; ++j) {
      d.push_back(&disps_[j + 1]);
      f.push_back(&flows_[j]);
    }
    SceneFlowParams p = plain();
    p.gaps = gaps;
    p.fit_velocity = fit;
    label_stereo_flow_window(disps_[0], d, f, cam_, {}, p, kDt, danger_, ttc_, vel_);
  }
  core::Camera cam_;
  std::vector<cv::Mat> disps_, flows_;
  cv::Mat danger_, ttc_, vel_;
};

TEST_F(FarApproach, InvisibleAtGapOne) {
  label({1}, 10);
  EXPECT_EQ(cv::countNonZero(danger_), 0);
  // The velocity is there (gap 1 is noise-free here), only the disparity gate rejects it.
  EXPECT_NEAR(vel_.at<cv::Vec3f>(75, 100)[2], -3.0, 0.05);
  label({1, 4}, 10);
  EXPECT_EQ(cv::countNonZero(danger_), 0);
}

TEST_F(FarApproach, CaughtAtGapTen) {
  label({1, 4, 10}, 10);
  const cv::Rect centre(90, 65, 21, 21);
  EXPECT_EQ(cv::countNonZero(danger_(centre)), centre.area());
  const double z_now = 60.0 / static_cast<float>(60.0 / 9.0);
  const double z_then = 60.0 / static_cast<float>(60.0 / 10.0);
  const double vz = (z_now - z_then) / (10 * kDt);
  EXPECT_NEAR(ttc_.at<float>(75, 100), (z_now - 0.5) / -vz, 1e-3);
  EXPECT_NEAR(vel_.at<cv::Vec3f>(75, 100)[2], -3.0, 1e-3);
  // Nothing outside the square.
  cv::Mat outside = danger_.clone();
  outside(square(9.0)).setTo(0);
  EXPECT_EQ(cv::countNonZero(outside), 0);
}

// A far surface's disparity error is largely common to its pixels and changes from frame to
// frame; the longest gap's difference keeps the errors of its two ends, the fit averages them over
// every frame of the chain. Here the square's disparity is off by +-0.06 px per frame (about a
// tenth of its 0.67 px growth over 10 frames), +0.06 now and -0.06 ten frames ago.
TEST_F(FarApproach, TheFitAveragesFrameErrorsThatTheLongestGapKeeps) {
  const float offsets[kFrames] = {0.06f,  -0.06f, 0.06f, 0.06f, -0.06f, 0.06f,
                                  -0.06f, -0.06f, 0.06f, 0.06f, -0.06f};
  for (int j = 0; j < kFrames; ++j) disps_[j](square(9.0 + 3.0 * kDt * j)) += offsets[j];
  label({10}, 10);
  const float two_point = vel_.at<cv::Vec3f>(75, 100)[2];
  label({10}, 10, true);
  const float fitted = vel_.at<cv::Vec3f>(75, 100)[2];
  EXPECT_GT(std::abs(two_point + 3.0), 0.4);  // the ends' errors: 0.12 px of 0.67
  EXPECT_LT(std::abs(fitted + 3.0), 0.5 * std::abs(two_point + 3.0));
  EXPECT_LT(std::abs(fitted + 3.0), 0.25);
}

TEST_F(FarApproach, TheFitFindsTheExactVelocityWithoutErrors) {
  label({10}, 10, true);
  EXPECT_NEAR(vel_.at<cv::Vec3f>(75, 100)[2], -3.0, 0.02);
  const cv::Rect centre(90, 65, 21, 21);
  EXPECT_EQ(cv::countNonZero(danger_(centre)), centre.area());
}

// One frame of the chain matched one period of a repetitive texture off (+3 px of 6.67, a
// checkerboard read nearer): the fit would take it for motion.
TEST_F(FarApproach, AMismatchedFrameOnTheChainLeavesTheVelocityUnknown) {
  disps_[4](square(9.0 + 3.0 * kDt * 4)) += 3.0f;
  label({10}, 10, true);
  EXPECT_TRUE(std::isnan(vel_.at<cv::Vec3f>(75, 100)[2]));
  // Inside the square every chain sampled the mismatch (at its border the bilinear sample mixes
  // the wall in and is skipped: those chains never saw it).
  const cv::Rect centre(90, 65, 21, 21);
  EXPECT_EQ(cv::countNonZero(danger_(centre)), 0);
  // The same in the current frame: nothing before it supports it.
  disps_[4](square(9.0 + 3.0 * kDt * 4)) -= 3.0f;
  disps_[0](square(9.0)) += 3.0f;
  label({10}, 10, true);
  EXPECT_TRUE(std::isnan(vel_.at<cv::Vec3f>(75, 100)[2]));
}

// The bounds: under chain_outlier_px (far) or under chain_outlier_fraction (near) a step stays
// in the fit.
TEST_F(FarApproach, StepsWithinEitherBoundStayInTheFit) {
  SceneFlowParams p = plain();
  p.gaps = {10};
  p.fit_velocity = true;
  disps_[4](square(9.0 + 3.0 * kDt * 4)) += 1.5f;  // 1.5 px < 2 px, though 23 % of the disparity
  std::vector<const cv::Mat*> d, f;
  for (int j = 0; j < 10; ++j) {
    d.push_back(&disps_[j + 1]);
    f.push_back(&flows_[j]);
  }
  label_stereo_flow_window(disps_[0], d, f, cam_, {}, p, kDt, danger_, ttc_, vel_);
  EXPECT_FALSE(std::isnan(vel_.at<cv::Vec3f>(75, 100)[2]));
  // The sample reads 7.9 px: 1.5 px is beyond both 1 px and 15 % of 7.9 px (1.2 px).
  p.chain_outlier_px = 1.0;
  p.chain_outlier_fraction = 0.15;
  label_stereo_flow_window(disps_[0], d, f, cam_, {}, p, kDt, danger_, ttc_, vel_);
  EXPECT_TRUE(std::isnan(vel_.at<cv::Vec3f>(75, 100)[2]));
  p.chain_outlier_fraction = 0.25;  // 25 % of 7.9 px (2.0 px): within the fraction
  label_stereo_flow_window(disps_[0], d, f, cam_, {}, p, kDt, danger_, ttc_, vel_);
  EXPECT_FALSE(std::isnan(vel_.at<cv::Vec3f>(75, 100)[2]));
  p.chain_outlier_px = 0.0;  // disabled
  p.chain_outlier_fraction = 0.0;
  label_stereo_flow_window(disps_[0], d, f, cam_, {}, p, kDt, danger_, ttc_, vel_);
  EXPECT_FALSE(std::isnan(vel_.at<cv::Vec3f>(75, 100)[2]));
}

TEST_F(FarApproach, GapTenNeedsTenFrames) {
  label({10}, 9);
  EXPECT_EQ(cv::countNonZero(danger_), 0);
  EXPECT_TRUE(std::isnan(vel_.at<cv::Vec3f>(75, 100)[0]));
}

// ---------------------------------------------------------------------------------------------
// Filters for real matchers: depth-edge margin, vertical band, longest gap

TEST(DepthEdges, HandComputedWindow) {
  // 15 x 9: a step of 3 px at column 7, one invalid pixel; ramp of 0.4 px a column on row 8.
  cv::Mat d(9, 15, CV_32F, cv::Scalar(2.0f));
  d(cv::Rect(7, 0, 8, 8)).setTo(5.0f);
  d.at<float>(1, 1) = -1.0f;
  cv::Mat mask;
  mark_depth_edges(d, 2, 1.0, mask);
  ASSERT_EQ(mask.type(), CV_8UC1);
  for (int x = 0; x < 15; ++x) {
    // Rows 0..5 only see the step: columns 5..8 have both sides within 2 px.
    const bool near = x >= 5 && x <= 8;
    EXPECT_EQ(mask.at<uint8_t>(3, x) != 0, near) << x;
  }
  EXPECT_EQ(mask.at<uint8_t>(1, 2), 0);  // the invalid neighbour does not count
  // A step of 3 px is not an edge for step_px = 3.5; margin 0 marks nothing.
  mark_depth_edges(d, 2, 3.5, mask);
  EXPECT_EQ(cv::countNonZero(mask), 0);
  mark_depth_edges(d, 0, 1.0, mask);
  EXPECT_EQ(cv::countNonZero(mask), 0);
}

TEST(LabelStereoFlow, EdgeMarginSparesThePatchBorder) {
  const core::Camera cam = odd_camera();  // f B = 20
  Maps m = wall(cam);
  const cv::Rect patch(60, 45, 31, 27);
  m.prev(patch).setTo(20.0 / 2.0);
  m.cur(patch).setTo(20.0 / 1.9);
  SceneFlowParams p = plain();
  p.edge_margin_px = 4;
  cv::Mat danger, ttc, vel;
  label_stereo_flow(m.cur, m.prev, m.flow, cam, {}, p, kDt, danger, ttc, vel);
  const cv::Rect inner(patch.x + 4, patch.y + 4, patch.width - 8, patch.height - 8);
  EXPECT_EQ(cv::countNonZero(danger(inner)), inner.area());
  EXPECT_EQ(cv::countNonZero(danger), inner.area());
  EXPECT_TRUE(std::isnan(vel.at<cv::Vec3f>(patch.y, patch.x)[2]));  // not a candidate
}

TEST(LabelStereoFlow, SourceNearAPastEdgeIsNotDangerous) {
  const core::Camera cam = odd_camera();
  Maps m = wall(cam);
  const cv::Rect now(60, 45, 31, 27);
  m.cur(now).setTo(20.0 / 1.9);
  // Before, the patch was 12 px to the left at 2 m, but the flow says 9 px (as flow does near
  // edges): the sources of the right part of the patch fall near, then beyond, its past edge.
  m.prev(now - cv::Point(12, 0)).setTo(20.0 / 2.0);
  m.flow(now).setTo(cv::Scalar(-9, 0));
  SceneFlowParams p = plain();
  p.edge_margin_px = 3;
  core::Envelope env;
  env.half_width_m = 3.0;  // the sideways drift must not matter here
  cv::Mat danger, ttc, vel;
  label_stereo_flow(m.cur, m.prev, m.flow, cam, env, p, kDt, danger, ttc, vel);
  // Current interior: x in [63, 88), rows [48, 69). The past patch spans [48, 79); q = x - 9
  // must lie 3 px inside it: q < 76, so x < 85.
  EXPECT_EQ(cv::countNonZero(danger), 22 * 21);
  EXPECT_EQ(danger.at<uint8_t>(58, 84), 255);
  EXPECT_EQ(danger.at<uint8_t>(58, 85), 0);
  EXPECT_NEAR(vel.at<cv::Vec3f>(58, 84)[2], -3.0, 1e-3);
  // A source near the past edge gives no velocity either (surface pooling must not use it).
  EXPECT_TRUE(std::isnan(vel.at<cv::Vec3f>(58, 85)[2]));
}

TEST(LabelStereoFlow, EnvelopeBandKeepsGroundPointsOut) {
  const core::Camera cam = odd_camera();
  Maps m = wall(cam);
  // A patch 3.8 m ahead, 0.9 m and more below the axis (down to the image's bottom row), moving
  // along the rays towards the camera: at contact every point is inside the envelope.
  const double z_now = 3.8, z_before = 3.9;
  const int y0 = static_cast<int>(std::ceil(cam.cy + 0.9 * cam.focal_px / z_now));
  const cv::Rect patch(60, y0, 20, cam.height - y0);
  m.cur(patch).setTo(20.0 / z_now);
  m.prev(patch).setTo(20.0 / z_before);
  SceneFlowParams p = plain();
  p.min_delta_d_px = 0.0;
  cv::Mat danger, ttc, vel;
  label_stereo_flow(m.cur, m.prev, m.flow, cam, {}, p, kDt, danger, ttc, vel);
  EXPECT_EQ(cv::countNonZero(danger), patch.area());
  // With the band only the rows with Y <= y_bottom = 1 m now: y <= cy + f / z = 110.4.
  p.use_envelope_band = true;
  label_stereo_flow(m.cur, m.prev, m.flow, cam, {}, p, kDt, danger, ttc, vel);
  EXPECT_EQ(cv::countNonZero(danger), patch.width * (110 - y0 + 1));
  EXPECT_EQ(danger.at<uint8_t>(110, 65), 255);
  EXPECT_EQ(danger.at<uint8_t>(111, 65), 0);
}

// ---------------------------------------------------------------------------------------------
// Ground plane

/// fit_ground_plane as a plain loop: every hypothesis counted over every point, then the same
/// least-squares refit.
GroundPlane fit_ground_plane_reference(const cv::Mat& disp, const core::Camera& cam,
                                       const GroundParams& p) {
  std::vector<cv::Point3d> pts;
  const int y0 = disp.rows - std::max(1, static_cast<int>(disp.rows * p.lower_fraction));
  for (int y = y0; y < disp.rows; y += p.sample_step_px)
    for (int x = 0; x < disp.cols; x += p.sample_step_px) {
      const float d = disp.at<float>(y, x);
      if (!(d > 0.0f)) continue;
      const cv::Point3d P = cam.point(x, y, d);
      if (P.z <= p.z_max_m) pts.push_back(P);
    }
  const auto count = [&](const cv::Vec3d& n, double c) {
    int inliers = 0;
    for (const auto& P : pts) inliers += std::abs(n.dot(cv::Vec3d(P)) + c) <= p.tolerance_m;
    return inliers;
  };
  GroundPlane best;
  std::mt19937_64 rng(p.seed);
  std::uniform_int_distribution<size_t> pick(0, pts.size() - 1);
  for (int it = 0; it < p.iterations; ++it) {
    const cv::Vec3d a(pts[pick(rng)]), b(pts[pick(rng)]), c(pts[pick(rng)]);
    cv::Vec3d n = (b - a).cross(c - a);
    const double len = cv::norm(n);
    if (len < 1e-9) continue;
    n /= len;
    if (n[1] > 0) n = -n;
    if (-n[1] < std::cos(CV_PI / 4)) continue;
    const int inliers = count(n, -n.dot(a));
    if (inliers > best.inliers) best = {n, -n.dot(a), inliers, false};
  }
  if (best.inliers < std::max(3, p.min_inliers)) return GroundPlane{};
  cv::Vec3d mean(0, 0, 0);
  std::vector<cv::Vec3d> in;
  for (const auto& P : pts)
    if (std::abs(best.normal.dot(cv::Vec3d(P)) + best.offset) <= p.tolerance_m) in.emplace_back(P);
  for (const auto& P : in) mean += P;
  mean /= static_cast<double>(in.size());
  cv::Matx33d cov = cv::Matx33d::zeros();
  for (const auto& P : in) cov += (P - mean) * (P - mean).t();
  cv::Mat evals, evecs;
  cv::eigen(cov, evals, evecs);
  cv::Vec3d n(evecs.at<double>(2, 0), evecs.at<double>(2, 1), evecs.at<double>(2, 2));
  if (n[1] > 0) n = -n;
  if (-n[1] >= std::cos(CV_PI / 4)) {
    best.normal = n;
    best.offset = -n.dot(mean);
    best.inliers = count(best.normal, best.offset);
  }
  best.found = best.inliers >= p.min_inliers;
  return best;
}


TEST(GroundPlane, FitsATiltedGroundAndSparesAnObstacle) {
  core::Camera cam = odd_camera();
  const double h = 1.0, pitch = 10.0 * CV_PI / 180.0;
  const cv::Vec3d up(0.0, -std::cos(pitch), -std::sin(pitch));  // world up in camera coords
  const double fb = cam.focal_px * cam.baseline_m;
  cv::Mat disp(cam.height, cam.width, CV_32F, cv::Scalar(-1.0f));
  cv::Mat truth_ground(disp.size(), CV_8U, cv::Scalar(0)), box(disp.size(), CV_8U, cv::Scalar(0));
  cv::RNG rng(17);
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const cv::Vec3d ray((x - cam.cx) / cam.focal_px, (y - cam.cy) / cam.focal_px, 1.0);
      // Box: the plane Z = 3 m, 0.6 m wide, standing on the ground up to 0.8 m.
      const cv::Vec3d on_box = ray * 3.0;
      const double box_height = up.dot(on_box) + h;
      if (std::abs(on_box[0]) <= 0.3 && box_height >= 0.0 && box_height <= 0.8) {
        disp.at<float>(y, x) = static_cast<float>(fb / 3.0);
        if (box_height > 0.1) box.at<uint8_t>(y, x) = 255;
        continue;
      }
      const double denom = -up.dot(ray);  // ray reaches the ground at t = h / denom
      if (denom <= 1e-3) continue;
      const double z = h / denom;
      if (z > 15.0) continue;
      disp.at<float>(y, x) = static_cast<float>(fb / z + rng.uniform(-0.02, 0.02));
      if (z < 8.0) truth_ground.at<uint8_t>(y, x) = 255;
    }
  const GroundPlane g = fit_ground_plane(disp, cam, GroundParams{});
  ASSERT_TRUE(g.found);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(g.normal[i], up[i], 0.02) << i;
  EXPECT_NEAR(g.offset, h, 0.03);
  cv::Mat mask;
  mark_ground(disp, cam, g, 0.05, mask);
  ASSERT_EQ(mask.type(), CV_8UC1);
  const int ground_px = cv::countNonZero(truth_ground);
  cv::Mat hit;
  cv::bitwise_and(mask, truth_ground, hit);
  EXPECT_GT(cv::countNonZero(hit), 0.97 * ground_px);
  cv::bitwise_and(mask, box, hit);
  ASSERT_GT(cv::countNonZero(box), 100);
  EXPECT_EQ(cv::countNonZero(hit), 0);
  // A reproducible fit: same seed, same plane.
  const GroundPlane again = fit_ground_plane(disp, cam, GroundParams{});
  EXPECT_EQ(again.normal, g.normal);
  EXPECT_EQ(again.offset, g.offset);
  // Counts that stop early pick the plane the plain loop picks, bit for bit.
  const GroundPlane reference = fit_ground_plane_reference(disp, cam, GroundParams{});
  EXPECT_EQ(reference.normal, g.normal);
  EXPECT_EQ(reference.offset, g.offset);
  EXPECT_EQ(reference.inliers, g.inliers);
  // Testing only some pixels marks those of them the full mask marks.
  cv::Mat only(disp.size(), CV_8U, cv::Scalar(0)), part, expected;
  only(cv::Rect(0, cam.height / 2, cam.width / 2, cam.height / 2)).setTo(255);
  mark_ground(disp, cam, g, 0.05, part, only);
  cv::bitwise_and(mask, only, expected);
  EXPECT_EQ(cv::countNonZero(part != expected), 0);
  EXPECT_GT(cv::countNonZero(part), 100);
}

// The ground's side: the plane's pixels, the far ground that the matcher reads up to margin_px
// too near (more than tolerance_m above the plane at a distance), and nothing of what stands
// on it beyond that. Against the disparity of the plane written out by hand, not mark_ground.
TEST(GroundPlane, TheGroundSideHoldsTheFarGroundsErrorButNotWhatStandsOnIt) {
  const core::Camera cam = odd_camera();
  const double h = 1.0, fb = cam.focal_px * cam.baseline_m;
  GroundPlane g;
  g.normal = {0.0, -1.0, 0.0};  // level ground 1 m below the camera: Y = 1
  g.offset = h;
  g.found = true;
  cv::Mat disp(cam.height, cam.width, CV_32F, cv::Scalar(-1.0f));
  const int y_far = static_cast<int>(cam.cy) + 3, y_near = cam.height - 2;
  const int x = static_cast<int>(cam.cx);
  // The plane's disparity at row y: Z = h f / (y - cy).
  auto ground_d = [&](int y) { return fb * (y - cam.cy) / (cam.focal_px * h); };
  cv::Mat out;
  auto side = [&](int y, double d, double margin) {
    disp.at<float>(y, x) = static_cast<float>(d);
    mark_ground_side(disp, cam, g, 0.05, margin, out);
    return out.at<uint8_t>(y, x) != 0;
  };
  // Far ground read 0.8 px too near: far above the 5-cm tolerance, inside the 1-px margin.
  EXPECT_TRUE(side(y_far, ground_d(y_far) + 0.8, 1.0));
  EXPECT_FALSE(side(y_far, ground_d(y_far) + 0.8, 0.0));
  EXPECT_FALSE(side(y_far, ground_d(y_far) + 1.2, 1.0));
  // Near, 3 cm above the plane (tolerance) and below it: ground; 0.3 m above: off it.
  const double d_near = ground_d(y_near);
  auto at_height = [&](double above) {  // the disparity of the point `above` m over the plane
    return d_near * h / (h - above);
  };
  EXPECT_TRUE(side(y_near, at_height(0.03), 0.0));
  EXPECT_TRUE(side(y_near, at_height(-0.2), 0.0));
  EXPECT_FALSE(side(y_near, at_height(0.3), 1.0));
  // Above the horizon nothing is on the ground's side; invalid pixels never are.
  EXPECT_FALSE(side(static_cast<int>(cam.cy) - 5, 2.0, 1.0));
  EXPECT_FALSE(side(y_near, -1.0, 1.0));
  // No plane found: nothing.
  disp.at<float>(y_near, x) = static_cast<float>(d_near);
  mark_ground_side(disp, cam, GroundPlane{}, 0.05, 1.0, out);
  EXPECT_EQ(cv::countNonZero(out), 0);
}

TEST(GroundPlane, NoPlaneWithoutPoints) {
  const core::Camera cam = odd_camera();
  const cv::Mat disp(cam.height, cam.width, CV_32F, cv::Scalar(-1.0f));
  EXPECT_FALSE(fit_ground_plane(disp, cam, GroundParams{}).found);
  cv::Mat mask;
  mark_ground(disp, cam, GroundPlane{}, 0.05, mask);
  EXPECT_EQ(cv::countNonZero(mask), 0);
}

}  // namespace
}  // namespace sg::vision
