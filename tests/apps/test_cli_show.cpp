// `run --show` on a virtual X server (Xvfb): the window shows the run's overlay frames; SIGINT
// still ends the run cleanly with the window open; q (typed with xdotool) ends it with status 0
// and a summary saying "interrupted". Skipped when Xvfb or xwd is not installed.
#include <gtest/gtest.h>

#include <climits>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

#include "cli_run.hpp"
#include "cli_spawn.hpp"

namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

bool on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (!path) return false;
  std::string dirs = path;
  for (size_t begin = 0; begin <= dirs.size();) {
    size_t end = dirs.find(':', begin);
    if (end == std::string::npos) end = dirs.size();
    if (access((dirs.substr(begin, end - begin) + "/" + program).c_str(), X_OK) == 0) return true;
    begin = end + 1;
  }
  return false;
}

uint32_t be32(const std::string& s, size_t at) {
  uint32_t v = 0;
  for (size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(s[at + i]);
  return v;
}

/// An XWD dump (X11 XWDFileHeader, version 7, ZPixmap, 3 or 4 bytes per pixel with 8-bit colour
/// masks, as Xvfb's 24-bit screen gives; byte order 0 = LSBFirst) as a BGR image; empty when the
/// format is another.
cv::Mat read_xwd(const std::string& data) {
  if (data.size() < 100) return {};
  const uint32_t header_size = be32(data, 0), version = be32(data, 4), format = be32(data, 8);
  const int width = static_cast<int>(be32(data, 16)), height = static_cast<int>(be32(data, 20));
  const uint32_t byte_order = be32(data, 28), bits_per_pixel = be32(data, 44);
  const uint32_t bytes_per_line = be32(data, 48), ncolors = be32(data, 76);
  const uint32_t red_mask = be32(data, 56), green_mask = be32(data, 60), blue_mask = be32(data, 64);
  // xwd may call the pixels 24 bits while storing each in 4 bytes: the line length decides.
  if (version != 7 || format != 2 || width <= 0 || (bits_per_pixel != 24 && bits_per_pixel != 32))
    return {};
  const uint32_t bytes_per_pixel = bytes_per_line / static_cast<uint32_t>(width);
  if (bytes_per_pixel != 3 && bytes_per_pixel != 4) return {};
  if (red_mask != 0xFF0000 || green_mask != 0xFF00 || blue_mask != 0xFF) return {};
  const size_t pixels = header_size + 12u * ncolors;  // XWDColor entries are 12 bytes
  if (data.size() < pixels + static_cast<size_t>(bytes_per_line) * height) return {};
  cv::Mat out(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t at = pixels + static_cast<size_t>(y) * bytes_per_line + bytes_per_pixel * x;
      uint32_t v = 0;
      for (size_t i = 0; i < bytes_per_pixel; ++i) {
        const uint32_t byte = static_cast<unsigned char>(data[at + i]);
        v |= byte_order == 0 ? byte << (8 * i) : byte << (8 * (bytes_per_pixel - 1 - i));
      }
      out.at<cv::Vec3b>(y, x) = cv::Vec3b(v & 0xFF, (v >> 8) & 0xFF, (v >> 16) & 0xFF);
    }
  }
  return out;
}

class CliShow : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!on_path("Xvfb") || !on_path("xwd")) {
      GTEST_SKIP() << "Xvfb or xwd not installed (Debian packages xvfb, x11-apps)";
    }
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) / ("sg_show_" + std::string(info->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // -displayfd: Xvfb picks a free display itself and writes its number once it accepts
    // clients, so parallel tests never race for one. -br: a uniform black root window.
    int fds[2];
    ASSERT_EQ(pipe(fds), 0);
    xvfb_ = sg::test::spawn({"Xvfb", "-displayfd", std::to_string(fds[1]), "-screen", "0",
                             "1280x1024x24", "-br", "-nolisten", "tcp"},
                            dir_, "", dir_ / "xvfb.txt");
    close(fds[1]);
    std::string number;
    char c;
    while (read(fds[0], &c, 1) == 1 && c != '\n') number += c;
    close(fds[0]);
    ASSERT_FALSE(number.empty()) << sg::test::slurp(dir_ / "xvfb.txt");
    display_ = ":" + number;
  }
  void TearDown() override {
    if (xvfb_ > 0) {
      kill(xvfb_, SIGTERM);
      sg::test::wait_exit(xvfb_, 30s);
    }
    if (!dir_.empty()) fs::remove_all(dir_);
  }

  pid_t start_run() {
    return sg::test::spawn(
        {SG_STEREOGUARD_BIN, "run", "--scenario", "head-on", "--show", "--fps", "10", "--quiet",
         "--events", "events.jsonl", "--overlay", "overlay.mp4", "--summary", "summary.json"},
        dir_, dir_ / "stdout.txt", dir_ / "stderr.txt",
        {"DISPLAY=" + display_, "WAYLAND_DISPLAY="});
  }

  /// The screen, read with xwd; empty when it could not be read (`why` says why).
  cv::Mat screenshot(std::string& why) {
    const pid_t pid = sg::test::spawn({"xwd", "-root", "-silent", "-display", display_}, dir_,
                                      dir_ / "screen.xwd", dir_ / "xwd.txt");
    const std::optional<int> status = sg::test::wait_exit(pid, 60s);
    if (!status || *status != 0) {
      why = "xwd status " + (status ? std::to_string(*status) : std::string("timeout")) + ": " +
            sg::test::slurp(dir_ / "xwd.txt");
      return {};
    }
    const std::string data = sg::test::slurp(dir_ / "screen.xwd");
    why = "unexpected XWD format (" + std::to_string(data.size()) + " bytes; header";
    for (size_t at = 0; at + 4 <= 100 && at + 4 <= data.size(); at += 4)
      why += " " + std::to_string(be32(data, at));
    why += ")";
    return read_xwd(data);
  }

  fs::path dir_;
  pid_t xvfb_ = -1;
  std::string display_;
};

/// The bounding box of the pixels unlike the bottom-right one (the root window: without a window
/// manager the window sits at the top left).
cv::Rect drawn_area(const cv::Mat& screen) {
  cv::Mat mask(screen.size(), CV_8U);
  const cv::Vec3b root = screen.at<cv::Vec3b>(screen.rows - 1, screen.cols - 1);
  for (int y = 0; y < screen.rows; ++y)
    for (int x = 0; x < screen.cols; ++x) {
      const cv::Vec3b p = screen.at<cv::Vec3b>(y, x);
      mask.at<uint8_t>(y, x) = p == root ? 0 : 255;
    }
  std::vector<cv::Point> points;
  cv::findNonZero(mask, points);
  return points.empty() ? cv::Rect() : cv::boundingRect(points);
}

/// `image` reduced to kThumb (area averages): what survives the window's scaling and the video's
/// compression, the layout and colours of the overlay.
const cv::Size kThumb(64, 48);
cv::Mat thumb(const cv::Mat& image) {
  cv::Mat out;
  cv::resize(image, out, kThumb, 0, 0, cv::INTER_AREA);
  return out;
}

double mean_difference(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  const cv::Scalar m = cv::mean(diff);
  return (m[0] + m[1] + m[2]) / 3.0;
}

/// Mean absolute difference per channel value between the thumbnails of `shown` and of the
/// closest frame of `video`.
double closest_frame_difference(const cv::Mat& shown, const fs::path& video) {
  cv::VideoCapture in(video.string());
  const cv::Mat s = thumb(shown);
  double best = 1e9;
  for (cv::Mat f; in.read(f) && !f.empty();) best = std::min(best, mean_difference(thumb(f), s));
  return best;
}

TEST_F(CliShow, WindowShowsTheOverlayAndSigintEndsTheRunCleanly) {
  const pid_t pid = start_run();
  ASSERT_TRUE(sg::test::wait_lines(dir_ / "events.jsonl", 5, pid, 300s))
      << sg::test::slurp(dir_ / "stderr.txt");
  // The window maps and takes its size asynchronously: poll the screen until the drawn area is
  // the same on two screenshots in a row.
  cv::Mat screen;
  cv::Rect area, before;
  for (int attempt = 0; attempt < 100 && (area.area() == 0 || area != before); ++attempt) {
    before = area;
    std::this_thread::sleep_for(200ms);
    std::string why;
    screen = screenshot(why);
    ASSERT_FALSE(screen.empty()) << why;
    area = drawn_area(screen);
  }
  ASSERT_GT(area.area(), 0) << "nothing drawn on the screen";
  ASSERT_EQ(kill(pid, SIGINT), 0);
  const std::optional<int> status = sg::test::wait_exit(pid, 300s);
  ASSERT_TRUE(status);
  EXPECT_EQ(*status, 130) << sg::test::slurp(dir_ / "stderr.txt");
  const nlohmann::json summary = nlohmann::json::parse(sg::test::slurp(dir_ / "summary.json"));
  EXPECT_TRUE(summary.at("interrupted").get<bool>());

  cv::VideoCapture probe((dir_ / "overlay.mp4").string());
  ASSERT_TRUE(probe.isOpened());
  const cv::Size frame(static_cast<int>(probe.get(cv::CAP_PROP_FRAME_WIDTH)),
                       static_cast<int>(probe.get(cv::CAP_PROP_FRAME_HEIGHT)));
  // The window (no window manager: no decorations) holds a picture of at least half the
  // overlay's size each way (Qt may scale it: 640x480 shows as 480x480 on this Xvfb), and that
  // picture looks like one of the overlay frames the run wrote (thumbnails compared), far more
  // than like the empty screen.
  EXPECT_GE(area.width, frame.width / 2) << area;
  EXPECT_GE(area.height, frame.height / 2) << area;
  EXPECT_LE(area.width, frame.width + 8) << area;
  EXPECT_LE(area.height, frame.height + 8) << area;
  const cv::Mat shown = screen(area);
  const double difference = closest_frame_difference(shown, dir_ / "overlay.mp4");
  const cv::Vec3b root = screen.at<cv::Vec3b>(screen.rows - 1, screen.cols - 1);
  const double from_empty =
      mean_difference(thumb(shown), cv::Mat(kThumb, CV_8UC3, cv::Scalar(root[0], root[1], root[2])));
  EXPECT_LT(difference, 12.0) << "the window does not show an overlay frame of the run";
  EXPECT_GT(from_empty, 4 * difference) << "the window looks like the empty screen";
}

TEST_F(CliShow, QuitKeyEndsTheRunWithStatusZeroAndInterrupted) {
  if (!on_path("xdotool")) GTEST_SKIP() << "xdotool not installed (Debian package xdotool)";
  const pid_t pid = start_run();
  ASSERT_TRUE(sg::test::wait_lines(dir_ / "events.jsonl", 5, pid, 300s))
      << sg::test::slurp(dir_ / "stderr.txt");
  // Focus the window (there is no window manager to do it) and type q; retried until the run
  // ends, since the first attempts may come before the window is mapped.
  std::optional<int> status;
  for (int attempt = 0; attempt < 60 && !status; ++attempt) {
    const pid_t key = sg::test::spawn({"xdotool", "search", "--name", "stereoguard",
                                       "windowfocus", "key", "q"},
                                      dir_, "", "", {"DISPLAY=" + display_});
    sg::test::wait_exit(key, 60s);
    if (!sg::test::running(pid)) status = sg::test::wait_exit(pid, 10s);
    else std::this_thread::sleep_for(500ms);
  }
  if (!status) status = sg::test::wait_exit(pid, 1s);
  ASSERT_TRUE(status) << "q did not end the run";
  EXPECT_EQ(*status, 0) << sg::test::slurp(dir_ / "stderr.txt");
  const nlohmann::json summary = nlohmann::json::parse(sg::test::slurp(dir_ / "summary.json"));
  EXPECT_TRUE(summary.at("interrupted").get<bool>());
  EXPECT_EQ(sg::test::complete_lines(dir_ / "events.jsonl"), summary.at("frames").get<int>());
}

}  // namespace
