// Thin structures and far objects in the Stereo-Flow clean-up (vision/edge_margin.hpp).
#include <gtest/gtest.h>

#include <cmath>

#include "sg/vision/detector.hpp"
#include "sg/vision/edge_margin.hpp"
#include "sg/vision/scene_flow.hpp"

namespace sg::vision {
namespace {

/// The default camera: 640 x 480, f 500 px, B 0.12 m, 30 fps.
const core::Camera kCam;

/// Background at 40 m everywhere, with a rectangle at depth z (pixel rectangle r).
cv::Mat scene_with(const cv::Rect& r, double z) {
  cv::Mat d(kCam.height, kCam.width, CV_32F, cv::Scalar(kCam.disparity(40.0)));
  d(r).setTo(kCam.disparity(z));
  return d;
}

TEST(ThinStructures, PoleIsMarkedButNotWideObjectsBordersOrTheFarSide) {
  const int margin = 8;
  cv::Mat d = scene_with({320, 100, 5, 200}, 5.0);           // a 5 px pole
  d(cv::Rect(100, 100, 60, 60)).setTo(kCam.disparity(6.0));  // a 60 px box
  d(cv::Rect(0, 300, 6, 40)).setTo(kCam.disparity(6.0));     // a strip at the image border
  d(cv::Rect(400, 50, 200, 12)).setTo(kCam.disparity(4.0));  // a 12 px high bar
  cv::Mat thin;
  mark_thin_structures(d, margin, 1.0, 2 * margin + 1, thin);
  EXPECT_EQ(thin.at<uchar>(200, 322), 255);  // pole
  EXPECT_EQ(thin.at<uchar>(200, 320), 255);
  EXPECT_EQ(thin.at<uchar>(56, 500), 255);  // bar (thin along its columns)
  EXPECT_EQ(thin.at<uchar>(200, 318), 0);   // background beside the pole: something nearer
  EXPECT_EQ(thin.at<uchar>(200, 330), 0);
  EXPECT_EQ(thin.at<uchar>(105, 105), 0);  // box corner: its runs are 60 px long
  EXPECT_EQ(thin.at<uchar>(320, 2), 0);    // the border strip may go on outside the image
  // The depth-edge mask loses the pole; unmark_thin_structures gives it back, and only it.
  cv::Mat edges;
  mark_depth_edges(d, margin, 1.0, edges);
  ASSERT_EQ(cv::countNonZero(edges(cv::Rect(320, 100, 5, 200))), 5 * 200);
  cv::Mat before = edges.clone();
  unmark_thin_structures(d, margin, 1.0, edges);
  EXPECT_EQ(cv::countNonZero(edges(cv::Rect(320, 100, 5, 200))), 0);
  EXPECT_EQ(
      cv::countNonZero(edges(cv::Rect(100, 100, 60, 60)) != before(cv::Rect(100, 100, 60, 60))), 0);
}

/// Stereo-Flow detector on exact maps of a robot approaching a pole at 2 m/s: frames 0..n-1
/// end with the pole's front 5 m away. The pole is 5 cm wide and stands at the image centre, so
/// it grows in the image but does not move: the backward flow is zero.
std::vector<core::Detection> approach_pole(core::SceneFlowParams sf, int frames) {
  core::DetectorParams params;
  params.mode = core::Mode::kStereoFlow;
  params.scene_flow = sf;
  Detector det(params, kCam);
  std::vector<core::Detection> out;
  for (int i = 0; i < frames; ++i) {
    const double z = 5.0 + 2.0 * (frames - 1 - i) / kCam.fps;
    const double half_px = kCam.focal_px * 0.025 / z;
    const int x0 = static_cast<int>(std::lround(kCam.cx - half_px));
    const int x1 = static_cast<int>(std::lround(kCam.cx + half_px));
    const cv::Mat d = scene_with({x0, 40, x1 - x0 + 1, 400}, z);
    core::StereoFrame f;
    f.index = i;
    f.time_s = i / kCam.fps;
    FrameMaps maps{d, i == 0 ? cv::Mat() : cv::Mat(d.size(), CV_32FC2, cv::Scalar(0, 0))};
    out.push_back(det.process(f, maps));
  }
  return out;
}

TEST(ThinStructures, FiveCentimetrePoleFiveMetresAheadKeepsItsDangerMask) {
  core::SceneFlowParams sf;
  const std::vector<core::Detection> out = approach_pole(sf, 25);
  const core::Detection& last = out.back();
  EXPECT_GT(cv::countNonZero(last.danger), 0);
  ASSERT_EQ(last.obstacles.size(), 1u);
  EXPECT_TRUE(last.signal);
  EXPECT_NEAR(last.obstacles[0].distance_m, 5.0, 0.1);
  ASSERT_TRUE(last.obstacles[0].ttc_s.has_value());
  EXPECT_NEAR(*last.obstacles[0].ttc_s, (5.0 - 0.5) / 2.0, 0.2);
  // The cause: without giving thin structures back, the edge margin removes the whole pole.
  sf.keep_thin_structures = false;
  EXPECT_EQ(cv::countNonZero(approach_pole(sf, 25).back().danger), 0);
}

TEST(DangerGrowth, FarObjectGrowsBackOverItsRimOnly) {
  // An object 30 x 25 px at 10 m (a car 30 m away at f 600 px is 36 x 30 px). Its interior,
  // outside the margin, is dangerous.
  const int margin = 8;
  const cv::Rect car(300, 220, 30, 25);
  const cv::Mat d = scene_with(car, 10.0);
  cv::Mat edges;
  mark_depth_edges(d, margin, 1.0, edges);
  cv::Mat danger = cv::Mat::zeros(d.size(), CV_8U);
  cv::Mat ttc(d.size(), CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  cv::Mat velocity(d.size(), CV_32FC3, cv::Scalar::all(std::numeric_limits<float>::quiet_NaN()));
  const cv::Rect interior(car.x + margin, car.y + margin, car.width - 2 * margin,
                          car.height - 2 * margin);
  ASSERT_EQ(cv::countNonZero(edges(interior)), 0);
  danger(interior).setTo(255);
  ttc(interior).setTo(2.5);
  velocity(interior).setTo(cv::Scalar(0, 0, -10));
  // A lone noisy pixel on the background: it must neither grow nor be removed here.
  danger.at<uchar>(car.y - 3, car.x + 200) = 255;
  cv::Mat grown = danger.clone();
  grow_danger_into_edges(d, edges, margin, 1.0, 3, grown, ttc, velocity);
  EXPECT_EQ(cv::countNonZero(grown(car)), car.area());  // the whole car
  cv::Mat outside = grown.clone();
  outside(car).setTo(0);
  EXPECT_EQ(cv::countNonZero(outside), 1);  // only the lone pixel, not grown
  EXPECT_FLOAT_EQ(ttc.at<float>(car.y, car.x), 2.5f);
  EXPECT_FLOAT_EQ(velocity.at<cv::Vec3f>(car.y, car.x)[2], -10.0f);
  // Without growth min_area (150 px) would drop the 14 x 9 px interior.
  EXPECT_LT(interior.area(), 150);
}

}  // namespace
}  // namespace sg::vision
