// Real-input sources, calibration files and rectification.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "calibration_text.hpp"
#include "io_test_util.hpp"
#include "sg/io/calibration.hpp"
#include "sg/io/source_factory.hpp"
#include "sg/io/sources.hpp"

namespace sg::io {
namespace {

namespace fs = std::filesystem;
using testing_util::input_error_of;
using testing_util::ScratchDir;

fs::path calibration_file(const fs::path& dir, const std::string& m1) {
  testing_util::write_calibration_text(dir / "bad.yaml", m1);
  return dir / "bad.yaml";
}

cv::Mat random_image(cv::Size size, int seed) {
  cv::Mat m(size, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(m, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(m, m, cv::Size(5, 5), 1.0);
  return m;
}

/// Writes `n` left/right PNG pairs of `size` under dir/left, dir/right.
void write_pairs(const fs::path& dir, int n, cv::Size size) {
  fs::create_directories(dir / "left");
  fs::create_directories(dir / "right");
  for (int i = 0; i < n; ++i) {
    const std::string name = "f" + std::to_string(100 + i) + ".png";
    cv::imwrite((dir / "left" / name).string(), random_image(size, 2 * i));
    cv::imwrite((dir / "right" / name).string(), random_image(size, 2 * i + 1));
  }
}

bool same(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::countNonZero(a != b) == 0;
}

/// Reads every frame of two fresh sources, one through next() and one through next_pending() +
/// load() (the loads run after all reads, as a pipeline may), and compares them.
template <typename Make>
void expect_next_equals_pending(Make make) {
  auto a = make();
  auto b = make();
  std::vector<core::PendingFrame> pending;
  while (auto p = b->next_pending()) pending.push_back(std::move(*p));
  int count = 0;
  for (const auto& p : pending) {
    const auto frame = a->next();
    ASSERT_TRUE(frame.has_value());
    const core::StereoFrame loaded = p.load();
    EXPECT_EQ(frame->index, p.index);
    EXPECT_EQ(loaded.index, p.index);
    EXPECT_DOUBLE_EQ(frame->time_s, p.time_s);
    EXPECT_DOUBLE_EQ(loaded.time_s, p.time_s);
    EXPECT_TRUE(same(frame->left, loaded.left)) << "frame " << p.index;
    EXPECT_TRUE(same(frame->right, loaded.right)) << "frame " << p.index;
    ++count;
  }
  EXPECT_FALSE(a->next().has_value());
  EXPECT_GT(count, 1);
}

/// A pinhole pair without distortion: rectification is the identity up to interpolation.
StereoCalibration ideal_calibration(cv::Size size, double f, double baseline) {
  StereoCalibration c;
  c.image_size = size;
  c.M1 = (cv::Mat_<double>(3, 3) << f, 0, (size.width - 1) / 2.0, 0, f, (size.height - 1) / 2.0, 0,
          0, 1);
  c.M2 = c.M1.clone();
  c.D1 = cv::Mat::zeros(1, 5, CV_64F);
  c.D2 = cv::Mat::zeros(1, 5, CV_64F);
  c.R = cv::Mat::eye(3, 3, CV_64F);
  c.T = (cv::Mat_<double>(3, 1) << -baseline, 0, 0);
  return c;
}

core::Camera rectified_camera() {
  core::Camera cam;
  cam.focal_px = 300;
  cam.baseline_m = 0.1;
  cam.fps = 20;
  return cam;
}

std::vector<ImagePair> pairs_of(const fs::path& dir, double fps) {
  const auto l = list_images((dir / "left").string()), r = list_images((dir / "right").string());
  std::vector<ImagePair> pairs;
  for (size_t i = 0; i < l.size(); ++i) pairs.push_back({l[i], r[i], i / fps});
  return pairs;
}

TEST(ImageListSource, NextEqualsPendingLoad) {
  ScratchDir dir;
  write_pairs(dir.path(), 5, {37, 23});
  expect_next_equals_pending([&] {
    return std::make_unique<ImageListSource>(pairs_of(dir.path(), 20), rectified_camera());
  });
}

TEST(ImageListSource, SizeAndPrincipalPointFromTheFirstFrame) {
  ScratchDir dir;
  write_pairs(dir.path(), 2, {37, 23});
  core::Camera cam = rectified_camera();
  cam.cx = cam.cy = std::nan("");
  ImageListSource source(pairs_of(dir.path(), 20), cam);
  EXPECT_EQ(source.camera().width, 37);
  EXPECT_EQ(source.camera().height, 23);
  EXPECT_DOUBLE_EQ(source.camera().cx, 18.0);
  EXPECT_DOUBLE_EQ(source.camera().cy, 11.0);
  EXPECT_EQ(source.size(), 2);
}

TEST(ImageListSource, FrameSizeChangingMidSequenceNamesTheFile) {
  ScratchDir dir;
  write_pairs(dir.path(), 3, {37, 23});
  cv::imwrite((dir.path() / "right" / "f102.png").string(), random_image({36, 23}, 9));
  ImageListSource source(pairs_of(dir.path(), 20), rectified_camera());
  ASSERT_TRUE(source.next().has_value());
  ASSERT_TRUE(source.next().has_value());
  const std::string message = input_error_of([&] { source.next(); });
  EXPECT_NE(message.find("f102.png is 36x23"), std::string::npos) << message;
}

TEST(ListImages, FolderGlobAndEmptyFolder) {
  ScratchDir dir;
  write_pairs(dir.path(), 3, {8, 8});
  std::ofstream(dir.path() / "left" / "notes.txt") << "not an image";
  EXPECT_EQ(list_images((dir.path() / "left").string()).size(), 3u);
  const auto glob = list_images((dir.path() / "left" / "f10?.png").string());
  ASSERT_EQ(glob.size(), 3u);
  EXPECT_EQ(glob[0].filename(), "f100.png");
  fs::create_directories(dir.path() / "empty");
  EXPECT_NE(input_error_of([&] {
              list_images((dir.path() / "empty").string());
            }).find("no images in folder"),
            std::string::npos);
  EXPECT_NE(input_error_of([&] {
              list_images((dir.path() / "x*.png").string());
            }).find("no images match"),
            std::string::npos);
}

TEST(FpsFromTimes, MedianIntervalIgnoresOneDroppedFrame) {
  EXPECT_DOUBLE_EQ(fps_from_times({0.0, 0.05, 0.10, 0.20, 0.25}), 20.0);
  EXPECT_DOUBLE_EQ(fps_from_times({0.0}), 0.0);
  EXPECT_DOUBLE_EQ(fps_from_times({1.0, 1.0}), 0.0);
}

TEST(Rectification, IdealPairIsTheIdentityAndGivesTheCamera) {
  const cv::Size size(64, 48);
  const auto r = make_rectification(ideal_calibration(size, 300, 0.1), size, "test");
  EXPECT_NEAR(r->camera.focal_px, 300, 1.0);  // alpha 0 may zoom a hair
  EXPECT_NEAR(r->camera.baseline_m, 0.1, 1e-9);
  EXPECT_NEAR(r->camera.cx, 31.5, 0.5);
  core::StereoFrame frame;
  frame.left = random_image(size, 1);
  frame.right = random_image(size, 2);
  const cv::Mat left = frame.left.clone();
  rectify(*r, frame);
  cv::Mat diff;
  cv::absdiff(frame.left(cv::Rect(4, 4, 56, 40)), left(cv::Rect(4, 4, 56, 40)), diff);
  double max_diff = 0;
  cv::minMaxLoc(diff, nullptr, &max_diff);
  EXPECT_LE(max_diff, 12.0);
}

TEST(Rectification, WrongImageSizeAndSwappedCamerasAreErrors) {
  const cv::Size size(64, 48);
  EXPECT_NE(input_error_of([&] {
              make_rectification(ideal_calibration(size, 300, 0.1), {80, 48}, "c.yaml");
            }).find("is for 64x48 images, the frames are 80x48"),
            std::string::npos);
  EXPECT_NE(input_error_of([&] {
              make_rectification(ideal_calibration(size, 300, -0.1), size, "c.yaml");
            }).find("swap left and right"),
            std::string::npos);
}

TEST(RectifiedSource, NextEqualsPendingLoad) {
  ScratchDir dir;
  write_pairs(dir.path(), 4, {40, 30});
  expect_next_equals_pending([&] {
    auto inner = std::make_unique<ImageListSource>(pairs_of(dir.path(), 20), rectified_camera());
    return std::make_unique<RectifiedSource>(std::move(inner),
                                             ideal_calibration({40, 30}, 200, 0.2), "test");
  });
}

TEST(CaptureSource, VideoNextEqualsPendingLoadAndIsLossless) {
  ScratchDir dir;
  const cv::Size size(40, 30);
  const fs::path left = dir.path() / "l.mkv", right = dir.path() / "r.mkv";
  std::vector<cv::Mat> frames;
  {
    cv::VideoWriter wl(left.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'),
                       20, size, false);
    cv::VideoWriter wr(right.string(), cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'),
                       20, size, false);
    if (!wl.isOpened() || !wr.isOpened()) GTEST_SKIP() << "no FFV1 encoder in this OpenCV";
    for (int i = 0; i < 4; ++i) {
      frames.push_back(random_image(size, i));
      wl.write(frames.back());
      wr.write(255 - frames.back());
    }
  }
  expect_next_equals_pending([&] {
    return CaptureSource::open_videos(left.string(), right.string(), rectified_camera());
  });
  auto source = CaptureSource::open_videos(left.string(), right.string(), rectified_camera());
  EXPECT_DOUBLE_EQ(source->camera().fps, 20.0);
  for (int i = 0; i < 4; ++i) {
    const auto f = source->next();
    ASSERT_TRUE(f.has_value());
    EXPECT_TRUE(same(f->left, frames[i])) << i;
    EXPECT_TRUE(same(f->right, 255 - frames[i])) << i;
    EXPECT_DOUBLE_EQ(f->time_s, i / 20.0);
  }
}

TEST(LiveFrameClock, IndicesCountCameraFramesFromTheStamps) {
  LiveFrameClock clock(20.0);  // 50 ms frames
  EXPECT_EQ(clock.index_of(100.000), 0);
  EXPECT_DOUBLE_EQ(clock.first_stamp(), 100.0);
  EXPECT_EQ(clock.index_of(100.051), 1);  // jitter rounds to the nearest frame
  EXPECT_EQ(clock.index_of(100.199), 4);  // frames 2 and 3 were lost: a gap of two
  EXPECT_EQ(clock.index_of(100.210), 5);  // too early for frame 5 still moves on, never repeats
  EXPECT_EQ(clock.index_of(100.190), 6);  // nor goes back
}

TEST(LiveFrameClock, AFrameIsStaleOnceItsSuccessorHasBeenCaptured) {
  const LiveFrameClock clock(20.0);
  EXPECT_FALSE(clock.stale(10.0, 10.0));
  EXPECT_FALSE(clock.stale(10.0, 10.049));
  EXPECT_TRUE(clock.stale(10.0, 10.050));
  EXPECT_TRUE(clock.stale(10.0, 10.5));
}

TEST(CaptureSource, MissingCameraIsAnError) {
  EXPECT_NE(input_error_of([] {
              CaptureSource::open_cameras(97, 98, core::Camera{});
            }).find("camera 97 not found"),
            std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// Calibration files

TEST(OpenCvCalibration, WriteReadRoundTrip) {
  ScratchDir dir;
  StereoCalibration c = ideal_calibration({640, 480}, 500, 0.12);
  c.D1.at<double>(0) = -0.2;
  write_opencv_calibration(dir.path() / "c.yaml", c);
  const StereoCalibration r = read_opencv_calibration(dir.path() / "c.yaml");
  EXPECT_EQ(r.image_size, cv::Size(640, 480));
  EXPECT_EQ(cv::norm(r.M1, c.M1), 0.0);
  EXPECT_EQ(cv::norm(r.D1, c.D1), 0.0);
  EXPECT_EQ(cv::norm(r.T, c.T), 0.0);
  EXPECT_TRUE(r.R1.empty());
  const Calibration any = read_calibration(dir.path() / "c.yaml");
  EXPECT_TRUE(any.stereo.has_value());
  EXPECT_FALSE(any.rectified.has_value());
}

TEST(OpenCvCalibration, MissingFieldNanAndSingularMatrixAreNamed) {
  ScratchDir dir;
  EXPECT_NE(input_error_of([&] {
              read_opencv_calibration(calibration_file(dir.path(), ""));
            }).find("missing field 'M1'"),
            std::string::npos);
  EXPECT_NE(
      input_error_of([&] {
        read_opencv_calibration(calibration_file(dir.path(), "250, 0, .nan, 0, 250, 120, 0, 0, 1"));
      }).find("calib.M1: has a value that is not finite"),
      std::string::npos);
  EXPECT_NE(
      input_error_of([&] {
        read_opencv_calibration(calibration_file(dir.path(), "250, 0, 160, 250, 0, 120, 0, 0, 1"));
      }).find("calib.M1: not an invertible camera matrix"),
      std::string::npos);
  const StereoCalibration good =
      read_opencv_calibration(calibration_file(dir.path(), "250, 0, 160, 0, 250, 120, 0, 0, 1"));
  EXPECT_EQ(good.image_size, cv::Size(0, 0));
}

TEST(OpenCvCalibration, RotationAndTranslationChecks) {
  StereoCalibration c = ideal_calibration({64, 48}, 300, 0.1);
  c.R.at<double>(0, 0) = 2;
  c.T = cv::Mat::zeros(3, 1, CV_64F);
  const auto problems = validate(c);
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_NE(problems[0].find("calib.R: not a rotation"), std::string::npos);
  EXPECT_NE(problems[1].find("calib.T"), std::string::npos);
}

TEST(KittiCalibration, RectifiedCameraFromPrect) {
  ScratchDir dir;
  const fs::path p = dir.path() / "calib_cam_to_cam.txt";
  std::ofstream(p)
      << "calib_time: 09-Jan-2012 13:57:47\n"
      << "S_rect_00: 1.242000e+03 3.750000e+02\n"
      << "P_rect_00: 7.215377e+02 0 6.095593e+02 0 0 7.215377e+02 1.728540e+02 0 0 0 1 0\n"
      << "P_rect_01: 7.215377e+02 0 6.095593e+02 -3.875744e+02 0 7.215377e+02 "
         "1.728540e+02 0 0 0 1 0\n";
  const core::Camera cam = read_kitti_calibration(p, 0, 1);
  EXPECT_EQ(cam.width, 1242);
  EXPECT_EQ(cam.height, 375);
  EXPECT_DOUBLE_EQ(cam.focal_px, 721.5377);
  EXPECT_NEAR(cam.baseline_m, 0.5372, 1e-4);
  EXPECT_DOUBLE_EQ(cam.cy, 172.854);
  EXPECT_NE(
      input_error_of([&] { read_kitti_calibration(p, 2, 3); }).find("missing key 'P_rect_02'"),
      std::string::npos);
}

TEST(SourceFactory, RectifiedInputNeedsACameraAndOneInput) {
  ScratchDir dir;
  write_pairs(dir.path(), 2, {16, 12});
  SourceSpec spec;
  spec.left = (dir.path() / "left").string();
  spec.right = (dir.path() / "right").string();
  spec.input_fps = 15;
  EXPECT_NE(input_error_of([&] { open_source(spec); }).find("no calibration"), std::string::npos);
  spec.focal_px = 100;
  spec.baseline_m = 0.2;
  const auto source = open_source(spec);
  EXPECT_DOUBLE_EQ(source->camera().fps, 15.0);
  EXPECT_DOUBLE_EQ(source->camera().cx, 7.5);
  spec.euroc = dir.path().string();
  EXPECT_NE(input_error_of([&] { open_source(spec); }).find("give one input"), std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// EuRoC (shared data)

fs::path euroc_dir() { return fs::path(SG_SHARED_DIR) / "data" / "euroc_v1_01_micro"; }

/// Median |row difference| of cross-checked ORB matches between left and right.
double median_row_difference(const cv::Mat& left, const cv::Mat& right) {
  auto orb = cv::ORB::create(2000);
  std::vector<cv::KeyPoint> kl, kr;
  cv::Mat dl, dr;
  orb->detectAndCompute(left, cv::noArray(), kl, dl);
  orb->detectAndCompute(right, cv::noArray(), kr, dr);
  cv::BFMatcher matcher(cv::NORM_HAMMING, true);
  std::vector<cv::DMatch> matches;
  matcher.match(dl, dr, matches);
  std::vector<double> rows;
  for (const auto& m : matches) {
    if (m.distance > 40) continue;
    rows.push_back(std::abs(kl[m.queryIdx].pt.y - kr[m.trainIdx].pt.y));
  }
  if (rows.size() < 50) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(rows.begin(), rows.begin() + rows.size() / 2, rows.end());
  return rows[rows.size() / 2];
}

TEST(Euroc, RectificationAlignsRowsOfOrbMatches) {
  if (!fs::is_directory(euroc_dir())) GTEST_SKIP() << "no EuRoC clip at " << euroc_dir();
  const fs::path mav0 = euroc_dir() / "mav0";
  const StereoCalibration calib =
      read_euroc_calibration(mav0 / "cam0" / "sensor.yaml", mav0 / "cam1" / "sensor.yaml");
  EXPECT_EQ(calib.image_size, cv::Size(752, 480));
  EXPECT_NEAR(cv::norm(calib.T), 0.11, 0.01);  // docs/inputs.md: "about 0.11 m"
  auto rectified = open_euroc(euroc_dir());
  EXPECT_EQ(rectified->size(), 95);
  EXPECT_NEAR(rectified->camera().fps, 20.0, 0.01);
  EXPECT_NEAR(rectified->camera().baseline_m, 0.11, 0.01);
  // The raw pairs, read as the rectified source pairs them.
  const auto raw_left = list_images((mav0 / "cam0" / "data").string());
  int checked = 0;
  for (int i = 0; i < 95; ++i) {
    const auto frame = rectified->next();
    ASSERT_TRUE(frame.has_value());
    if (i % 45 != 0) continue;
    const fs::path right_file = mav0 / "cam1" / "data" / raw_left[i].filename();
    ASSERT_TRUE(fs::exists(right_file));
    const cv::Mat raw_l = cv::imread(raw_left[i].string(), cv::IMREAD_GRAYSCALE);
    const cv::Mat raw_r = cv::imread(right_file.string(), cv::IMREAD_GRAYSCALE);
    const double before = median_row_difference(raw_l, raw_r);
    const double after = median_row_difference(frame->left, frame->right);
    std::printf("EuRoC frame %d: median ORB row difference %.2f px raw, %.2f px rectified\n", i,
                before, after);
    EXPECT_GT(before, 2.0) << "frame " << i;
    EXPECT_LT(after, 1.0) << "frame " << i;
    ++checked;
  }
  EXPECT_EQ(checked, 3);
  EXPECT_FALSE(rectified->next().has_value());
}

TEST(Euroc, NextEqualsPendingLoad) {
  if (!fs::is_directory(euroc_dir())) GTEST_SKIP() << "no EuRoC clip at " << euroc_dir();
  // Three frames are enough: the decorator chain is what is compared.
  struct FirstFrames : core::FrameSource {
    std::unique_ptr<core::FrameSource> inner = open_euroc(euroc_dir());
    int left = 3;
    std::optional<core::StereoFrame> next() override {
      return left-- > 0 ? inner->next() : std::nullopt;
    }
    std::optional<core::PendingFrame> next_pending() override {
      return left-- > 0 ? inner->next_pending() : std::nullopt;
    }
    const core::Camera& camera() const override { return inner->camera(); }
  };
  expect_next_equals_pending([] { return std::make_unique<FirstFrames>(); });
}

}  // namespace
}  // namespace sg::io
