// The labelling of the surveyed detectors (vision/surveyed.hpp) on hand-built maps: what each
// marks dangerous, with which TTC, and what it leaves alone.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "sg/core/error.hpp"
#include "sg/vision/surveyed.hpp"
#include "synthetic.hpp"

namespace sg::vision {
namespace {

constexpr double kDt = 1.0 / 30.0;

/// Backward flow: zero outside `box`; inside, the forward field F = (k (x - foe.x) + u,
/// k (y - foe.y)), so B = -F.
cv::Mat backward(cv::Size size, cv::Rect box, double k, cv::Point2d foe, double u) {
  cv::Mat flow(size, CV_32FC2, cv::Scalar::all(0));
  for (int y = box.y; y < box.y + box.height; ++y)
    for (int x = box.x; x < box.x + box.width; ++x)
      flow.at<cv::Vec2f>(y, x) = cv::Vec2f(static_cast<float>(-(k * (x - foe.x) + u)),
                                           static_cast<float>(-(k * (y - foe.y))));
  return flow;
}

int count(const cv::Mat& mask, cv::Rect r) { return cv::countNonZero(mask(r)); }

TEST(ExpansionRate, IsTheScaleRateOfAnAffineFieldWhateverItsFocusAndTranslation) {
  const cv::Size size(120, 90);
  const cv::Rect all(0, 0, 120, 90);
  const cv::Mat mask(size, CV_8U, cv::Scalar(255));
  for (const double k : {0.03, -0.01, 0.0}) {
    cv::Mat forward = -backward(size, all, k, {100, 20}, 2.5);
    EXPECT_NEAR(expansion_rate(forward, mask), k, 1e-6) << k;
  }
  EXPECT_EQ(expansion_rate(cv::Mat(size, CV_32FC2, cv::Scalar::all(0)),
                           cv::Mat::zeros(size, CV_8U)),
            0.0);
}

TEST(MotionParallaxDetector, FiresOnAnOffCentreExpansionAndNotOnATranslation) {
  const cv::Size size(320, 240);
  const core::MotionParallaxParams p;
  const cv::Rect box(200, 30, 80, 70);  // right of and above the centre
  cv::Mat danger, ttc;
  // 2 % a frame about the box's own centre: TTC = dt / k = 1.67 s.
  label_motion_parallax(backward(size, box, 0.02, {240, 65}, 0.0), kDt, p, 150, 3.0, danger,
                        ttc);
  const cv::Rect inner(box.x + 10, box.y + 10, box.width - 20, box.height - 20);
  EXPECT_EQ(count(danger, inner), inner.area());
  EXPECT_EQ(cv::countNonZero(danger), count(danger, box + cv::Size(10, 10) - cv::Point(5, 5)));
  EXPECT_NEAR(ttc.at<float>(65, 240), kDt / 0.02, 0.05 * kDt / 0.02);
  // The same box sliding sideways at 3 px a frame: it moves but does not grow.
  label_motion_parallax(backward(size, box, 0.0, {240, 65}, 3.0), kDt, p, 150, 3.0, danger, ttc);
  EXPECT_EQ(cv::countNonZero(danger), 0);
  // Shrinking (receding), and growing too slowly for the horizon (TTC 6.7 s > 3 s).
  label_motion_parallax(backward(size, box, -0.02, {240, 65}, 0.0), kDt, p, 150, 3.0, danger,
                        ttc);
  EXPECT_EQ(cv::countNonZero(danger), 0);
  label_motion_parallax(backward(size, box, 0.005, {240, 65}, 0.0), kDt, p, 150, 3.0, danger,
                        ttc);
  EXPECT_EQ(cv::countNonZero(danger), 0);
  EXPECT_THROW(label_motion_parallax(cv::Mat(4, 4, CV_32F), kDt, p, 1, 3.0, danger, ttc),
               core::InputError);
  EXPECT_THROW(label_motion_parallax(backward(size, box, 0.0, {0, 0}, 0.0), 0.0, p, 1, 3.0,
                                     danger, ttc),
               core::InputError);
}

TEST(ProximityLabelling, MarksNearPointsInTheEnvelopeOnly) {
  core::Camera cam;  // 640x480, f 500, B 0.12: d = 60 / Z
  core::Envelope e;  // |X| <= 0.5, -1 <= Y <= 1
  core::ProximityParams p;  // 4 m
  cv::Mat disp(cam.height, cam.width, CV_32F, cv::Scalar(cam.disparity(10.0)));
  // 0.4 m squares: 3 m ahead in the envelope, 3 m ahead 1.2 m to the right, 6 m ahead.
  auto square = [&](double X, double Y, double Z) {
    const cv::Point2d c = cam.project({X, Y, Z});
    const int half = static_cast<int>(cam.focal_px * 0.2 / Z);
    const cv::Rect r(static_cast<int>(c.x) - half, static_cast<int>(c.y) - half, 2 * half,
                     2 * half);
    disp(r).setTo(cam.disparity(Z));
    return r;
  };
  const cv::Rect ahead = square(-0.25, 0.3, 3.0), beside = square(1.2, 0.0, 3.0);
  const cv::Rect far = square(0.25, -0.3, 6.0);
  ASSERT_TRUE((ahead & far).empty());
  cv::Mat danger, ttc;
  label_proximity(disp, cv::Mat(), cam, e, p, danger, ttc);
  EXPECT_EQ(count(danger, ahead), ahead.area());
  EXPECT_EQ(count(danger, beside), 0);
  EXPECT_EQ(count(danger, far), 0);
  EXPECT_EQ(cv::countNonZero(danger), count(danger, ahead));
  EXPECT_TRUE(std::isnan(ttc.at<float>(ahead.y + 5, ahead.x + 5)));
  // A mask keeps only what it allows.
  cv::Mat allowed = cv::Mat::zeros(disp.size(), CV_8U);
  allowed(cv::Rect(ahead.x, ahead.y, ahead.width / 2, ahead.height)).setTo(255);
  label_proximity(disp, allowed, cam, e, p, danger, ttc);
  EXPECT_EQ(cv::countNonZero(danger), cv::countNonZero(allowed & danger));
  EXPECT_GT(cv::countNonZero(danger), 0);
  EXPECT_THROW(label_proximity(cv::Mat(), cv::Mat(), cam, e, p, danger, ttc), core::InputError);
}

using test::texture;

TEST(SceneFlowSegLabelling, AnApproachingPatchIsDangerousAPassingOneAndTheBackgroundAreNot) {
  core::Camera cam;
  cam.width = 320;
  cam.height = 240;
  cam.cx = 159.5;
  cam.cy = 119.5;
  const core::Envelope e;
  const core::SceneFlowSegParams p;
  const cv::Mat left = texture({320, 240}, 4, 1.5);
  const cv::Rect patch(130, 90, 60, 60);
  // Background 12 m away, still. The patch: from 6.0 m to 4.8 m over 0.2 s (6 m/s; one frame
  // at 30 Hz moves it by less than the disparity noise hides).
  const double dt = 0.2;
  cv::Mat prev(240, 320, CV_32F, cv::Scalar(cam.disparity(12.0)));
  cv::Mat cur = prev.clone();
  prev(cv::Rect(patch.x + 6, patch.y + 6, 48, 48)).setTo(cam.disparity(6.0));  // 0.8 the size
  cur(patch).setTo(cam.disparity(4.8));
  const cv::Mat still(240, 320, CV_32FC2, cv::Scalar::all(0));
  cv::Mat danger, ttc, velocity;
  label_sceneflow_seg(left, cur, prev, still, dt, cam, e, p, 150, danger, ttc, velocity);
  const cv::Rect inner(patch.x + 8, patch.y + 8, patch.width - 16, patch.height - 16);
  EXPECT_GT(count(danger, inner), inner.area() * 9 / 10);
  // The background stays static (the cut's grid rounds the patch's outline by a cell).
  EXPECT_LE(cv::countNonZero(danger), (patch.width + 8) * (patch.height + 8));
  // TTC = (4.8 - 0.5) / 6.
  EXPECT_NEAR(ttc.at<float>(120, 160), 4.3 / 6.0, 0.05);
  EXPECT_NEAR(velocity.at<cv::Vec3f>(120, 160)[2], -6.0, 0.3);

  // The patch 6 m ahead moving right at 1.5 m/s (0.3 m, 25 px over dt), beside the envelope
  // (X from 1.5 m): it moves, but not into the envelope.
  cv::Mat side_prev(240, 320, CV_32F, cv::Scalar(cam.disparity(12.0)));
  cv::Mat side_cur = side_prev.clone();
  const cv::Rect at(250, 90, 60, 60);
  side_prev(at - cv::Point(25, 0)).setTo(cam.disparity(6.0));
  side_cur(at).setTo(cam.disparity(6.0));
  cv::Mat flow(240, 320, CV_32FC2, cv::Scalar::all(0));
  flow(at).setTo(cv::Scalar(-25.0, 0.0));
  label_sceneflow_seg(left, side_cur, side_prev, flow, dt, cam, e, p, 150, danger, ttc,
                      velocity);
  EXPECT_EQ(cv::countNonZero(danger), 0);
  EXPECT_NEAR(velocity.at<cv::Vec3f>(120, 280)[0], 1.5, 0.1);  // it was seen to move
  EXPECT_THROW(label_sceneflow_seg(left, cur, prev, still, 0.0, cam, e, p, 150, danger, ttc,
                                   velocity),
               core::InputError);
}

TEST(RelativeSizeLabelling, AGrowingSquareIsDangerousWithTheTtcOfItsScale) {
  // A textured square before a static background grows by 12 % over 0.33 s: TTC = 0.33 / 0.12.
  const auto frame = test::square_before_background;
  const double span = 10 * kDt;
  const core::RelativeSizeParams p;
  cv::Mat danger, ttc;
  label_relative_size(frame(140.0), frame(140.0 * 1.12), span, p, 3.0, danger, ttc);
  const cv::Rect square(240 - 79, 180 - 79, 158, 158);
  EXPECT_GT(count(danger, square), square.area() / 8);
  EXPECT_LT(cv::countNonZero(danger) - count(danger, square), square.area() / 8);
  cv::Mat where;
  cv::findNonZero(danger, where);
  ASSERT_FALSE(where.empty());
  EXPECT_NEAR(ttc.at<float>(where.at<cv::Point>(0)), span / 0.12, 0.1 * span / 0.12);
  // Unchanged frames: nothing grows.
  label_relative_size(frame(140.0), frame(140.0), span, p, 3.0, danger, ttc);
  EXPECT_EQ(cv::countNonZero(danger), 0);
  // A TTC beyond the horizon is not dangerous (here 2.75 s against a 1 s horizon).
  label_relative_size(frame(140.0), frame(140.0 * 1.12), span, p, 1.0, danger, ttc);
  EXPECT_EQ(cv::countNonZero(danger), 0);
}

}  // namespace
}  // namespace sg::vision
