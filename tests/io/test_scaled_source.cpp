// --scale: the resizing decorator, its camera (cv::resize's pixel-centre convention), its checks,
// and next() against next_pending() + load().
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "io_test_util.hpp"
#include "sg/io/scaled_source.hpp"

namespace sg::io {
namespace {

using testing_util::input_error_of;

/// An 8-bit image of `size` holding one Gaussian spot of `sigma` px centred on `centre`.
cv::Mat spot_image(cv::Size size, cv::Point2d centre, double sigma) {
  cv::Mat img(size, CV_8UC1);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      const double r2 = (x - centre.x) * (x - centre.x) + (y - centre.y) * (y - centre.y);
      img.at<uchar>(y, x) = cv::saturate_cast<uchar>(250.0 * std::exp(-r2 / (2 * sigma * sigma)));
    }
  return img;
}

/// Intensity-weighted centroid of `img`, px.
cv::Point2d centroid(const cv::Mat& img) {
  const cv::Moments m = cv::moments(img);
  return {m.m10 / m.m00, m.m01 / m.m00};
}

/// Frames whose decode is deferred to load(), like a file source; every pixel textured by index.
class DeferredSource : public core::FrameSource {
 public:
  DeferredSource(int frames, cv::Size size) : frames_(frames) {
    camera_.width = size.width;
    camera_.height = size.height;
    camera_.cx = 101.3;
    camera_.cy = 70.6;
  }
  std::optional<core::StereoFrame> next() override {
    std::optional<core::PendingFrame> p = next_pending();
    if (!p) return std::nullopt;
    return p->load();
  }
  std::optional<core::PendingFrame> next_pending() override {
    if (next_ == frames_) return std::nullopt;
    core::PendingFrame p;
    p.index = next_;
    p.time_s = next_ * 0.1;
    p.load = [i = next_, size = cv::Size(camera_.width, camera_.height)] {
      core::StereoFrame f;
      f.index = i;
      f.time_s = i * 0.1;
      f.left.create(size, CV_8UC1);
      f.right.create(size, CV_8UC1);
      cv::RNG rng(1234 + i);
      rng.fill(f.left, cv::RNG::UNIFORM, 0, 256);
      rng.fill(f.right, cv::RNG::UNIFORM, 0, 256);
      return f;
    };
    ++next_;
    return p;
  }
  const core::Camera& camera() const override { return camera_; }
  int size() const override { return frames_; }

 private:
  core::Camera camera_;
  int frames_;
  int next_ = 0;
};

// The scaled camera's principal point lands where cv::resize puts the pixel that was at the
// original principal point: (c + 0.5) * s - 0.5, not c * s.
TEST(ScaledSource, PrincipalPointFollowsResizePixelCentres) {
  const cv::Size size(321, 241);  // odd: the actual factors differ from S
  for (double scale : {0.5, 0.73, 1.7}) {
    DeferredSource inner(1, size);
    const core::Camera before = inner.camera();
    const cv::Mat original = spot_image(size, {before.cx, before.cy}, 4.0);
    const cv::Point2d measured_before = centroid(original);
    ASSERT_NEAR(measured_before.x, before.cx, 0.02);
    ASSERT_NEAR(measured_before.y, before.cy, 0.02);

    const cv::Size to = scaled_size(size, scale);
    const core::Camera after = scale_camera(before, to);
    cv::Mat resized;
    cv::resize(original, resized, to, 0, 0, scale < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
    const cv::Point2d measured = centroid(resized);
    EXPECT_NEAR(measured.x, after.cx, 0.05) << "scale " << scale;
    EXPECT_NEAR(measured.y, after.cy, 0.05) << "scale " << scale;
    // The naive c * s convention is measurably off (by (s - 1) / 2 px), so this test can fail.
    const double sx = static_cast<double>(to.width) / size.width;
    EXPECT_GT(std::abs(measured.x - before.cx * sx), 0.1) << "scale " << scale;
    EXPECT_EQ(after.width, to.width);
    EXPECT_EQ(after.height, to.height);
    EXPECT_DOUBLE_EQ(after.focal_px, before.focal_px * sx);
    EXPECT_DOUBLE_EQ(after.baseline_m, before.baseline_m);
    EXPECT_DOUBLE_EQ(after.fps, before.fps);
  }
}

TEST(ScaledSource, ReportsTheScaledCameraAndResizesFrames) {
  ScaledSource source(std::make_unique<DeferredSource>(2, cv::Size(321, 241)), 0.5);
  EXPECT_EQ(source.camera().width, 161);  // 160.5 rounds up
  EXPECT_EQ(source.camera().height, 121);
  EXPECT_EQ(source.size(), 2);
  std::optional<core::StereoFrame> f = source.next();
  ASSERT_TRUE(f);
  EXPECT_EQ(f->left.size(), cv::Size(161, 121));
  EXPECT_EQ(f->right.size(), cv::Size(161, 121));
  EXPECT_EQ(f->left.type(), CV_8UC1);
}

TEST(ScaledSource, NextAndNextPendingGiveTheSameFrames) {
  for (double scale : {0.5, 1.3}) {
    ScaledSource a(std::make_unique<DeferredSource>(4, cv::Size(201, 99)), scale);
    ScaledSource b(std::make_unique<DeferredSource>(4, cv::Size(201, 99)), scale);
    std::vector<core::PendingFrame> pending;
    while (auto p = b.next_pending()) pending.push_back(std::move(*p));
    ASSERT_EQ(pending.size(), 4u);
    std::vector<core::StereoFrame> direct;
    while (auto f = a.next()) direct.push_back(std::move(*f));
    ASSERT_EQ(direct.size(), 4u);
    for (int i : {3, 1, 0, 2}) {  // loaded out of order, as the farm may
      const core::StereoFrame f = pending[i].load();
      EXPECT_EQ(pending[i].index, i);
      EXPECT_DOUBLE_EQ(pending[i].time_s, direct[i].time_s);
      EXPECT_EQ(f.index, direct[i].index);
      EXPECT_EQ(cv::norm(f.left, direct[i].left, cv::NORM_INF), 0.0) << i;
      EXPECT_EQ(cv::norm(f.right, direct[i].right, cv::NORM_INF), 0.0) << i;
    }
  }
}

TEST(ScaledSource, ScaleOneIsTheSourceItself) {
  auto inner = std::make_unique<DeferredSource>(1, cv::Size(100, 80));
  core::FrameSource* raw = inner.get();
  EXPECT_EQ(scale_source(std::move(inner), 1.0).get(), raw);
}

TEST(ScaledSource, RejectsBadScales) {
  const cv::Size vga(640, 480);
  for (double bad : {0.0, -1.0, 4.01, 100.0, std::nan(""), HUGE_VAL, -HUGE_VAL}) {
    const auto problems = validate_scale(bad, vga);
    ASSERT_EQ(problems.size(), 1u) << bad;
    EXPECT_EQ(problems[0].rfind("scale=", 0), 0u) << problems[0];
    EXPECT_NE(problems[0].find("(0, 4]"), std::string::npos) << problems[0];
  }
  EXPECT_TRUE(validate_scale(4.0, vga).empty());
  EXPECT_TRUE(validate_scale(0.1, vga).empty());  // 64 x 48, the smallest accepted
  const auto tiny = validate_scale(0.09, vga);
  ASSERT_EQ(tiny.size(), 1u);
  EXPECT_NE(tiny[0].find("58x43"), std::string::npos) << tiny[0];
  const std::string message = input_error_of(
      [] { ScaledSource s(std::make_unique<DeferredSource>(1, cv::Size(640, 480)), 0.0); });
  EXPECT_NE(message.find("scale=0"), std::string::npos) << message;
}

/// A stream whose second frame changes size.
class ResizingStream : public core::FrameSource {
 public:
  std::optional<core::StereoFrame> next() override {
    if (next_ == 2) return std::nullopt;
    const cv::Size size = next_ == 0 ? cv::Size(200, 100) : cv::Size(100, 100);
    core::StereoFrame f;
    f.index = next_++;
    f.left = cv::Mat(size, CV_8UC1, cv::Scalar(7));
    f.right = f.left.clone();
    return f;
  }
  const core::Camera& camera() const override { return camera_; }

 private:
  core::Camera camera_{.width = 200, .height = 100};
  int next_ = 0;
};

// A frame of another size is an error, not silently resized into shape.
TEST(ScaledSource, FrameOfAnotherSizeIsAnError) {
  ScaledSource source(std::make_unique<ResizingStream>(), 0.8);
  ASSERT_TRUE(source.next());
  const std::string message = input_error_of([&] { source.next(); });
  EXPECT_NE(message.find("frame 1 is 100x100"), std::string::npos) << message;
}

}  // namespace
}  // namespace sg::io
