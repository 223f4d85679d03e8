#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <opencv2/videoio.hpp>

#include "io_test_util.hpp"
#include "sg/io/overlay.hpp"

namespace sg::io {
namespace {

namespace fs = std::filesystem;
using testing_util::input_error_of;
using testing_util::ScratchDir;

constexpr int kWidth = 101;
constexpr int kHeight = 77;

core::StereoFrame flat_frame(int index, uchar value) {
  core::StereoFrame f;
  f.index = index;
  f.left = cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(value));
  f.right = f.left.clone();
  return f;
}

core::Detection sample_detection(int frame) {
  core::Detection d;
  d.frame = frame;
  d.signal = true;
  d.severity = core::Severity::kWarning;
  d.steering = core::Steering::kRight;
  d.regions = {{"left", true, 300}, {"centre", false, 0}, {"right", false, 0}};
  core::Obstacle o;
  o.bbox = cv::Rect(20, 45, 25, 24);
  o.pixels = 200;
  o.distance_m = 4.2;
  o.ttc_s = 1.3;
  d.obstacles = {o};
  d.danger = cv::Mat::zeros(kHeight, kWidth, CV_8UC1);
  d.danger(cv::Rect(70, 50, 15, 12)).setTo(255);
  return d;
}

TEST(Overlay, SizeAndType) {
  const cv::Mat out = draw_overlay(flat_frame(3, 100), sample_detection(3));
  EXPECT_EQ(out.type(), CV_8UC3);
  EXPECT_EQ(out.size(), cv::Size(kWidth, kHeight));
}

TEST(Overlay, DangerPixelIsReddenedOthersUntouched) {
  const cv::Mat out = draw_overlay(flat_frame(3, 100), sample_detection(3));
  const cv::Vec3b danger = out.at<cv::Vec3b>(55, 77);
  EXPECT_GT(danger[2], 150);  // red up
  EXPECT_LT(danger[0], 60);   // blue and green down
  EXPECT_LT(danger[1], 60);
  EXPECT_EQ(out.at<cv::Vec3b>(72, 95), cv::Vec3b(100, 100, 100));  // outside every drawing
}

TEST(Overlay, RegionCellsAndBoxColours) {
  const cv::Mat out = draw_overlay(flat_frame(3, 100), sample_detection(3));
  // Cells: 3 over 101 px; row 2 is inside the fill, above the names.
  EXPECT_EQ(out.at<cv::Vec3b>(2, 16), cv::Vec3b(0, 0, 255));   // left fired: red
  EXPECT_EQ(out.at<cv::Vec3b>(2, 50), cv::Vec3b(0, 160, 0));   // centre: green
  EXPECT_EQ(out.at<cv::Vec3b>(2, 84), cv::Vec3b(0, 160, 0));   // right: green
  EXPECT_EQ(out.at<cv::Vec3b>(60, 20), cv::Vec3b(0, 0, 255));  // left edge of the box
}

TEST(Overlay, VelocityAddsASecondLabelLine) {
  core::Detection plain = sample_detection(3);
  core::Detection with_velocity = plain;
  with_velocity.obstacles[0].velocity = cv::Vec3d(0.1, 0.0, -3.0);
  const cv::Mat a = draw_overlay(flat_frame(3, 100), plain);
  const cv::Mat b = draw_overlay(flat_frame(3, 100), with_velocity);
  auto black = [](const cv::Mat& img) {
    cv::Mat mask;
    cv::inRange(img, cv::Scalar(0, 0, 0), cv::Scalar(0, 0, 0), mask);
    return cv::countNonZero(mask);
  };
  // The label's black background is one line taller: by about one text height times the width
  // of the label.
  EXPECT_GT(black(b), black(a) + 5 * 20);
}

TEST(Overlay, NoRegionsNoDangerStillDraws) {
  core::Detection d;
  const cv::Mat out = draw_overlay(flat_frame(0, 50), d);
  EXPECT_EQ(out.size(), cv::Size(kWidth, kHeight));
  EXPECT_EQ(out.at<cv::Vec3b>(60, 50), cv::Vec3b(50, 50, 50));
}

int count_frames_opencv(const fs::path& file) {
  cv::VideoCapture cap(file.string());
  if (!cap.isOpened()) return -1;
  int n = 0;
  cv::Mat img;
  while (cap.read(img)) ++n;
  return n;
}

/// nb_read_frames from ffprobe, or -1 when ffprobe is not available.
int count_frames_ffprobe(const fs::path& file) {
  if (std::system("command -v ffprobe >/dev/null 2>&1") != 0) return -1;
  const std::string cmd = "ffprobe -v error -count_frames -select_streams v:0 "
                          "-show_entries stream=nb_read_frames -of csv=p=0 '" +
                          file.string() + "'";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (pipe == nullptr) return -1;
  std::array<char, 64> buf{};
  std::string text;
  while (fgets(buf.data(), buf.size(), pipe) != nullptr) text += buf.data();
  pclose(pipe);
  return text.empty() ? -2 : std::stoi(text);
}

TEST(OverlayWriter, FrameCountMatches) {
  ScratchDir tmp;
  const fs::path file = tmp.path() / "overlay.mp4";
  const int n = 7;
  {
    OverlayWriter w(file, cv::Size(kWidth, kHeight), 10.0);
    for (int i = 0; i < n; ++i) w.write(flat_frame(i, static_cast<uchar>(20 * i)), sample_detection(i));
    EXPECT_EQ(w.frames_written(), n);
    w.close();
    EXPECT_THROW(w.write(flat_frame(0, 0), sample_detection(0)), core::InputError);
  }
  ASSERT_TRUE(fs::exists(file));
  EXPECT_EQ(count_frames_opencv(file), n);
  const int probed = count_frames_ffprobe(file);
  if (probed == -1) GTEST_SKIP() << "ffprobe not available";
  EXPECT_EQ(probed, n);
}

TEST(OverlayWriter, UncreatablePath) {
  ScratchDir tmp;
  const fs::path bad = tmp.path() / "no_such_dir" / "overlay.mp4";
  const std::string msg = input_error_of([&] { OverlayWriter w(bad, cv::Size(64, 48), 10.0); });
  EXPECT_NE(msg.find(bad.string()), std::string::npos) << msg;
}

}  // namespace
}  // namespace sg::io
