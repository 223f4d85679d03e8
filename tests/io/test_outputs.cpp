// Per-frame outputs: the metrics CSV, the PNG dumps (disparity colour map, flow colour wheel,
// danger mask) and the progress line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "io_test_util.hpp"
#include "sg/io/csv_metrics.hpp"
#include "sg/io/dump.hpp"
#include "sg/io/progress.hpp"

namespace sg::io {
namespace {

namespace fs = std::filesystem;
using testing_util::input_error_of;
using testing_util::ScratchDir;

core::Detection sample_detection() {
  core::Detection d;
  d.frame = 42;
  d.time_s = 1.4;
  d.signal = true;
  d.severity = core::Severity::kDanger;
  d.steering = core::Steering::kLeft;
  d.regions = {{"left", false, 10}, {"centre", true, 300}, {"right", true, 200}};
  core::Obstacle far, near;
  far.distance_m = 7.25;
  far.ttc_s = 2.5;
  near.distance_m = 3.1234;
  near.ttc_s = 1.25;
  core::Obstacle no_ttc;
  no_ttc.distance_m = 9.0;
  d.obstacles = {far, near, no_ttc};
  d.latency_ms = 12.3456;
  return d;
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out(1);
  for (char c : line) {
    if (c == ',')
      out.emplace_back();
    else
      out.back() += c;
  }
  return out;
}

TEST(CsvMetrics, RowHoldsTheFrameMetrics) {
  EXPECT_EQ(csv_row(sample_detection(), true),
            "42,1.4000,1,danger,left,centre right,510,3,3.123,1.250,12.346");
  EXPECT_EQ(csv_row(sample_detection(), false),
            "42,1.4000,1,danger,left,centre right,510,3,3.123,1.250,");
  core::Detection quiet;
  quiet.frame = 3;
  quiet.time_s = 0.1;
  EXPECT_EQ(csv_row(quiet, true), "3,0.1000,0,none,straight,,0,0,,,0.000");
  EXPECT_EQ(split(kCsvHeader).size(), split(csv_row(sample_detection(), true)).size());
}

// Each row is flushed when written: a run that dies later leaves complete rows.
TEST(CsvMetrics, WriterFlushesEveryRowUnderTheHeader) {
  ScratchDir dir;
  const fs::path file = dir.path() / "m.csv";
  CsvWriter writer(file, true);
  writer.write(sample_detection());
  std::ifstream in(file);  // read while the writer is still open
  std::string header, row, extra;
  ASSERT_TRUE(std::getline(in, header));
  ASSERT_TRUE(std::getline(in, row));
  EXPECT_FALSE(std::getline(in, extra));
  EXPECT_EQ(header, kCsvHeader);
  EXPECT_EQ(row, csv_row(sample_detection(), true));
}

TEST(CsvMetrics, UnwritablePathNamesTheOption) {
  ScratchDir dir;
  const std::string message =
      input_error_of([&] { CsvWriter w(dir.path() / "missing" / "m.csv", true); });
  EXPECT_EQ(message.rfind("--csv", 0), 0u) << message;
}

/// BGR of a one-pixel flow field (u, v) coloured with radius scale `max_radius`.
cv::Vec3b flow_color(float u, float v, double max_radius = 1.0) {
  const cv::Mat flow(1, 1, CV_32FC2, cv::Scalar(u, v));
  return colorize_flow(flow, max_radius).at<cv::Vec3b>(0, 0);
}

void expect_bgr(cv::Vec3b got, int b, int g, int r) {
  EXPECT_NEAR(got[0], b, 2) << got;
  EXPECT_NEAR(got[1], g, 2) << got;
  EXPECT_NEAR(got[2], r, 2) << got;
}

// The Middlebury wheel: right red, down yellow, left cyan, up blue-violet; white at rest; paler
// for shorter vectors; darker beyond the radius scale.
TEST(FlowColors, FollowTheMiddleburyWheel) {
  expect_bgr(flow_color(0, 0), 255, 255, 255);
  expect_bgr(flow_color(1, 0), 0, 0, 255);
  expect_bgr(flow_color(0, 1), 0, 229, 255);   // between wheel entries 13 and 14 (RY)
  expect_bgr(flow_color(-1, 0), 255, 208, 0);  // wheel entry 27 (CB)
  expect_bgr(flow_color(0, -1), 255, 0, 88);   // between 40 and 41 (BM)
  expect_bgr(flow_color(0.5f, 0), 127, 127, 255);
  expect_bgr(flow_color(2, 0), 0, 0, 191);  // beyond the scale: 0.75 of the hue
  expect_bgr(flow_color(4, 0, 4.0), 0, 0, 255);
  expect_bgr(flow_color(NAN, 0), 0, 0, 0);
}

TEST(FlowColors, AutomaticScaleIsTheLargestMagnitude) {
  cv::Mat flow(2, 3, CV_32FC2, cv::Scalar(0, 0));
  flow.at<cv::Vec2f>(0, 1) = {-3, 4};  // |f| = 5, the largest
  flow.at<cv::Vec2f>(1, 2) = {2.5f, 0};
  flow.at<cv::Vec2f>(1, 0) = {NAN, NAN};
  const cv::Mat color = colorize_flow(flow);
  ASSERT_EQ(color.size(), flow.size());
  ASSERT_EQ(color.type(), CV_8UC3);
  expect_bgr(color.at<cv::Vec3b>(1, 2), 127, 127, 255);  // half of the largest, to the right
  expect_bgr(color.at<cv::Vec3b>(1, 0), 0, 0, 0);
  expect_bgr(color.at<cv::Vec3b>(0, 0), 255, 255, 255);
}

TEST(FlowColors, ScaleOverAMaskIgnoresPixelsOutsideIt) {
  cv::Mat flow(2, 2, CV_32FC2, cv::Scalar(0.5f, 0));
  flow.at<cv::Vec2f>(0, 0) = {30, 40};  // 50 px, outside the mask
  flow.at<cv::Vec2f>(1, 1) = {0, 3};
  cv::Mat mask(2, 2, CV_8U, cv::Scalar(255));
  mask.at<uchar>(0, 0) = 0;
  EXPECT_DOUBLE_EQ(flow_color_scale(flow), 50.0);
  EXPECT_DOUBLE_EQ(flow_color_scale(flow, mask), 3.0);
  EXPECT_DOUBLE_EQ(flow_color_scale(cv::Mat(2, 2, CV_32FC2, cv::Scalar(0.1f, 0))), 1.0);  // floor
}

TEST(DisparityColors, InvalidBlackNearRedFarBlueClampedAboveTheMaximum) {
  cv::Mat disp = (cv::Mat_<float>(1, 4) << -1.f, 0.f, 64.f, 500.f);
  const cv::Mat color = colorize_disparity(disp, 64.0);
  ASSERT_EQ(color.type(), CV_8UC3);
  expect_bgr(color.at<cv::Vec3b>(0, 0), 0, 0, 0);
  const cv::Vec3b far = color.at<cv::Vec3b>(0, 1), near = color.at<cv::Vec3b>(0, 2);
  EXPECT_GT(far[0], far[2]);    // blue over red
  EXPECT_GT(near[2], near[0]);  // red over blue
  EXPECT_EQ(color.at<cv::Vec3b>(0, 3), near);
}

TEST(DumpWriter, WritesThePngsOfAFrameNamedByIndex) {
  ScratchDir dir;
  const fs::path out = dir.path() / "a" / "b";  // created with its parents
  DumpWriter writer(out, 64.0);
  core::Detection d;
  d.frame = 7;
  d.danger = cv::Mat(30, 40, CV_8UC1, cv::Scalar(0));
  d.danger(cv::Rect(5, 5, 10, 10)).setTo(255);
  d.disparity = cv::Mat(30, 40, CV_32F, cv::Scalar(20));
  writer.write(d);
  EXPECT_EQ(writer.path("danger", 7), out / "danger_000007.png");
  const cv::Mat danger = cv::imread((out / "danger_000007.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(danger.empty());
  EXPECT_EQ(cv::norm(danger, d.danger, cv::NORM_INF), 0.0);
  const cv::Mat disp = cv::imread((out / "disparity_000007.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(disp.empty());
  EXPECT_EQ(cv::norm(disp, colorize_disparity(d.disparity, 64.0), cv::NORM_INF), 0.0);
  EXPECT_FALSE(fs::exists(out / "flow_000007.png"));  // no flow in this frame
  d.frame = 8;
  d.flow = cv::Mat(30, 40, CV_32FC2, cv::Scalar(1, 0));
  writer.write(d);
  EXPECT_TRUE(fs::exists(out / "flow_000008.png"));
}

TEST(DumpWriter, AFileOrAnUncreatableFolderIsAnError) {
  ScratchDir dir;
  const fs::path file = dir.path() / "file";
  std::ofstream(file) << "x";
  std::string message = input_error_of([&] { DumpWriter w(file, 64.0); });
  EXPECT_NE(message.find("--dump"), std::string::npos) << message;
  EXPECT_NE(message.find("not a directory"), std::string::npos) << message;
  message = input_error_of([&] { DumpWriter w(file / "sub", 64.0); });
  EXPECT_NE(message.find("--dump"), std::string::npos) << message;
  EXPECT_NE(message.find("cannot create"), std::string::npos) << message;
}

TEST(Progress, LineShowsCountRateAndTimeLeft) {
  // 57 of 143 in 2 s: 28.5 fps, 86 frames left = 3.0 s; bar 57 * 20 / 143 = 7 of 20.
  EXPECT_EQ(progress_line(57, 143, 2.0),
            "[#######.............]  57/143 frames  28.5 fps  ETA 0:03");
  EXPECT_EQ(progress_line(57, -1, 2.0), "57 frames  28.5 fps");
  EXPECT_EQ(progress_line(0, 10, 0.0), "[....................]  0/10 frames");
  EXPECT_EQ(progress_line(10, 10, 0.5), "[####################]  10/10 frames  20.0 fps  ETA 0:00");
  EXPECT_EQ(progress_line(1, 1001, 1.0),
            "[....................]  1/1001 frames  1.0 fps  ETA 16:40");
  // Another unit (eval --suite counts scenes): its name and "<unit>/s".
  EXPECT_EQ(progress_line(3, 10, 6.0, "scenes"),
            "[######..............]  3/10 scenes  0.5 scenes/s  ETA 0:14");
}

TEST(Progress, BarRedrawsInPlaceAtMostAtItsRateAndErasesItself) {
  std::ostringstream out;
  ProgressBar bar(out, 3, std::chrono::hours(1));
  bar.tick();  // first: drawn
  bar.tick();  // too soon: not drawn
  bar.tick();  // last: drawn
  const std::string s = out.str();
  EXPECT_EQ(std::count(s.begin(), s.end(), '\r'), 2) << s;
  EXPECT_NE(s.find("1/3 frames"), std::string::npos);
  EXPECT_EQ(s.find("2/3 frames"), std::string::npos);
  EXPECT_NE(s.find("3/3 frames"), std::string::npos);
  EXPECT_EQ(s.find('\n'), std::string::npos);
  bar.finish();
  EXPECT_EQ(out.str().substr(s.size()), "\r\033[K");
  bar.finish();  // nothing drawn since: nothing to erase
  EXPECT_EQ(out.str().size(), s.size() + 4);
}

}  // namespace
}  // namespace sg::io
