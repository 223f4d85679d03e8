#include <gtest/gtest.h>

#include <thread>

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "io_test_util.hpp"
#include "sg/io/stereo_folder.hpp"

namespace sg::io {
namespace {

namespace fs = std::filesystem;
using testing_util::input_error_of;
using testing_util::ScratchDir;

constexpr int kWidth = 37;  // odd sizes on purpose
constexpr int kHeight = 23;

core::Camera test_camera() {
  core::Camera c;
  c.width = kWidth;
  c.height = kHeight;
  c.focal_px = 41.3;
  c.baseline_m = 0.1234567;
  c.cx = 18.25;
  c.cy = 11.0 / 3.0;  // not exactly representable in short decimal
  c.fps = 12.5;
  return c;
}

cv::Mat random_image(cv::RNG& rng, int type, double lo, double hi) {
  cv::Mat m(kHeight, kWidth, type);
  rng.fill(m, cv::RNG::UNIFORM, lo, hi);
  return m;
}

struct Written {
  std::vector<core::StereoFrame> frames;
  std::vector<core::FrameTruth> truth;
  std::vector<core::TruthMaps> maps;
};

/// Writes `n` random frames with truth and maps into `dir`.
Written write_folder(const fs::path& dir, int n, bool with_truth = true) {
  cv::RNG rng(1234);
  Written w;
  FolderWriter writer(dir, test_camera(), with_truth);
  for (int i = 0; i < n; ++i) {
    core::StereoFrame f;
    f.index = i;
    f.left = random_image(rng, CV_8UC1, 0, 256);
    f.right = random_image(rng, CV_8UC1, 0, 256);
    core::FrameTruth t;
    t.frame = i;
    t.alarm = i % 2 == 1;
    t.obstacles.push_back({1, true, 2.5 - 0.1 * i, 100 + i});
    t.obstacles.push_back({7, false, std::nullopt, 3});
    core::TruthMaps m;
    m.disparity = random_image(rng, CV_32FC1, 0, 200);
    m.disparity.at<float>(3, 4) = 0.0f;  // unknown
    if (i > 0) m.flow = random_image(rng, CV_32FC2, -5, 5);
    m.danger = random_image(rng, CV_8UC1, 0, 2) * 255;
    m.ids = random_image(rng, CV_16UC1, 0, 9);
    writer.write(f, &t, &m);
    w.frames.push_back(f);
    w.truth.push_back(t);
    w.maps.push_back(m);
  }
  EXPECT_EQ(writer.frames_written(), n);
  return w;
}

void expect_equal_mats(const cv::Mat& a, const cv::Mat& b) {
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.type(), b.type());
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
}

TEST(FrameFileName, ZeroPadsToSixDigits) {
  EXPECT_EQ(frame_file_name(0, ".png"), "000000.png");
  EXPECT_EQ(frame_file_name(12, ".flo"), "000012.flo");
  EXPECT_EQ(frame_file_name(1234567, ".png"), "1234567.png");
}

TEST(StereoFolder, WriteReadRoundTrip) {
  ScratchDir tmp;
  const fs::path dir = tmp.path() / "seq";
  const int n = 4;
  const Written w = write_folder(dir, n);

  FolderSource src(dir);
  EXPECT_EQ(src.size(), n);
  const core::Camera& cam = src.camera();
  const core::Camera ref = test_camera();
  EXPECT_EQ(cam.width, kWidth);
  EXPECT_EQ(cam.height, kHeight);
  EXPECT_EQ(cam.focal_px, ref.focal_px);
  EXPECT_EQ(cam.baseline_m, ref.baseline_m);
  EXPECT_EQ(cam.cx, ref.cx);
  EXPECT_EQ(cam.cy, ref.cy);
  EXPECT_EQ(cam.fps, ref.fps);
  ASSERT_TRUE(src.has_truth());

  for (int i = 0; i < n; ++i) {
    auto f = src.next();
    ASSERT_TRUE(f.has_value()) << i;
    EXPECT_EQ(f->index, i);
    EXPECT_DOUBLE_EQ(f->time_s, i / ref.fps);
    expect_equal_mats(f->left, w.frames[i].left);
    expect_equal_mats(f->right, w.frames[i].right);

    const core::FrameTruth& t = src.truth(i);
    EXPECT_EQ(t.frame, w.truth[i].frame);
    EXPECT_EQ(t.alarm, w.truth[i].alarm);
    ASSERT_EQ(t.obstacles.size(), w.truth[i].obstacles.size());
    for (size_t k = 0; k < t.obstacles.size(); ++k) {
      EXPECT_EQ(t.obstacles[k].id, w.truth[i].obstacles[k].id);
      EXPECT_EQ(t.obstacles[k].colliding, w.truth[i].obstacles[k].colliding);
      EXPECT_EQ(t.obstacles[k].ttc_s, w.truth[i].obstacles[k].ttc_s);
      EXPECT_EQ(t.obstacles[k].pixels, w.truth[i].obstacles[k].pixels);
    }

    const core::TruthMaps m = src.truth_maps(i);
    ASSERT_EQ(m.disparity.type(), CV_32FC1);
    EXPECT_LE(cv::norm(m.disparity, w.maps[i].disparity, cv::NORM_INF), 1.0 / 256.0);
    EXPECT_EQ(m.disparity.at<float>(3, 4), 0.0f);
    if (i == 0) {
      EXPECT_TRUE(m.flow.empty());
      EXPECT_FALSE(fs::exists(dir / "gt" / "flow" / "000000.flo"));
    } else {
      expect_equal_mats(m.flow, w.maps[i].flow);
    }
    expect_equal_mats(m.danger, w.maps[i].danger);
    expect_equal_mats(m.ids, w.maps[i].ids);
  }
  EXPECT_FALSE(src.next().has_value());
  EXPECT_FALSE(src.next().has_value());
  input_error_of([&] { src.truth(n + 3); });

  // One complete line per frame.
  std::ifstream lines(dir / "gt" / "frames.jsonl");
  std::string line;
  int count = 0;
  while (std::getline(lines, line)) ++count;
  EXPECT_EQ(count, n);
}

TEST(StereoFolder, WithoutTruthHasNoGtFolder) {
  ScratchDir tmp;
  const fs::path dir = tmp.path() / "seq";
  write_folder(dir, 2, /*with_truth=*/false);
  EXPECT_FALSE(fs::exists(dir / "gt"));
  FolderSource src(dir);
  EXPECT_FALSE(src.has_truth());
  const core::TruthMaps m = src.truth_maps(0);
  EXPECT_TRUE(m.disparity.empty() && m.flow.empty() && m.danger.empty() && m.ids.empty());
}

TEST(StereoFolder, ColourAnd16BitImagesBecome8BitGray) {
  ScratchDir tmp;
  const fs::path dir = tmp.path() / "seq";
  write_folder(dir, 1, false);
  cv::Mat colour(kHeight, kWidth, CV_8UC3, cv::Scalar(10, 200, 60));
  cv::Mat gray16(kHeight, kWidth, CV_16UC1, cv::Scalar(257 * 77));
  ASSERT_TRUE(cv::imwrite((dir / "left" / "000000.png").string(), colour));
  ASSERT_TRUE(cv::imwrite((dir / "right" / "000000.png").string(), gray16));
  FolderSource src(dir);
  auto f = src.next();
  ASSERT_TRUE(f);
  ASSERT_EQ(f->left.type(), CV_8UC1);
  ASSERT_EQ(f->right.type(), CV_8UC1);
  cv::Mat expected;
  cv::cvtColor(colour, expected, cv::COLOR_BGR2GRAY);
  expect_equal_mats(f->left, expected);
  EXPECT_EQ(f->right.at<uchar>(5, 5), 77);
}

TEST(StereoFolder, IgnoresNonPngFilesAndSortsByName) {
  ScratchDir tmp;
  const fs::path dir = tmp.path() / "seq";
  const Written w = write_folder(dir, 3, false);
  std::ofstream(dir / "left" / "notes.txt") << "hello";
  std::ofstream(dir / "right" / "Thumbs.db") << "x";
  FolderSource src(dir);
  EXPECT_EQ(src.size(), 3);
  for (int i = 0; i < 3; ++i) {
    auto f = src.next();
    ASSERT_TRUE(f);
    expect_equal_mats(f->left, w.frames[i].left);
  }
}

TEST(CameraYaml, WriteReadRoundTripIgnoresWidthHeight) {
  ScratchDir tmp;
  const fs::path file = tmp.path() / "camera.yaml";
  write_camera_yaml(file, test_camera());
  const core::Camera c = read_camera_yaml(file, cv::Size(101, 55));
  EXPECT_EQ(c.width, 101);
  EXPECT_EQ(c.height, 55);
  EXPECT_EQ(c.cy, test_camera().cy);
}

// ---- bad input: one test each -------------------------------------------------------------

TEST(StereoFolderErrors, MissingFolder) {
  ScratchDir tmp;
  const fs::path dir = tmp.path() / "nope";
  const std::string msg = input_error_of([&] { FolderSource src(dir); });
  EXPECT_NE(msg.find("not found"), std::string::npos) << msg;
  EXPECT_NE(msg.find(dir.string()), std::string::npos) << msg;
}

TEST(StereoFolderErrors, NotAFolder) {
  ScratchDir tmp;
  const fs::path file = tmp.path() / "file.txt";
  std::ofstream(file) << "x";
  const std::string msg = input_error_of([&] { FolderSource src(file); });
  EXPECT_NE(msg.find("not a folder"), std::string::npos) << msg;
}

TEST(StereoFolderErrors, MissingCameraYaml) {
  ScratchDir tmp;
  const fs::path dir = tmp.path() / "seq";
  write_folder(dir, 2, false);
  fs::remove(dir / "camera.yaml");
  const std::string msg = input_error_of([&] { FolderSource src(dir); });
  EXPECT_NE(msg.find("missing camera file"), std::string::npos) << msg;
  EXPECT_NE(msg.find("camera.yaml"), std::string::npos) << msg;
}

TEST(StereoFolderErrors, UnparsableCameraYaml) {
  ScratchDir tmp;
  const fs::path dir = tmp.path() / "seq";
  write_folder(dir, 2, false);
  std::ofstream(dir / "camera.yaml") << "focal_px: [1, 2\nbaseline_m: {{{\n";
  const std::string msg = input_error_of([&] { FolderSource src(dir); });
  EXPECT_NE(msg.find("cannot parse"), std::string::npos) << msg;
  EXPECT_NE(msg.find("camera.yaml"), std::string::npos) << msg;
}

TEST(StereoFolderErrors, CameraYamlMissingField) {
  ScratchDir tmp;
  const fs::path dir = tmp.path() / "seq";
  write_folder(dir, 2, false);
  std::ofstream(dir / "camera.yaml") << "focal_px: 400\ncx: 18\ncy: 11\nfps: 10\n";
  const std::string msg = input_error_of([&] { FolderSource src(dir); });
  EXPECT_NE(msg.find("missing field 'baseline_m'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("camera.yaml"), std::string::npos) << msg;
}

TEST(StereoFolderErrors, CameraYamlFieldNotANumber) {
  ScratchDir tmp;
  const fs::path dir = tmp.path() / "seq";
  write_folder(dir, 2, false);
  std::ofstream(dir / "camera.yaml") << "focal_px: 400\nbaseline_m: 0.1\ncx: abc\ncy: 11\nfps: 10\n";
  const std::string msg = input_error_of([&] { FolderSource src(dir); });
  EXPECT_NE(msg.find("'cx' is not a number"), std::string::npos) << msg;
}

TEST(StereoFolderErrors, NegativeFps) {
  ScratchDir tmp;
  const fs::path dir = tmp.path() / "seq";
  write_folder(dir, 2, false);
  std::ofstream(dir / "camera.yaml") << "focal_px: 400\nbaseline_m: 0.1\ncx: 18\ncy: 11\nfps: -5\n";
  const std::string msg = input_error_of([&] { FolderSource src(dir); });
  EXPECT_NE(msg.find("camera.fps=-5"), std::string::npos) << msg;
  EXPECT_NE(msg.find("camera.yaml"), std::string::npos) << msg;
}

TEST(StereoFolderErrors, MissingRightFolder) {
  ScratchDir tmp;
  const fs::path dir = tmp.path() / "seq";
  write_folder(dir, 2, false);
  fs::remove_all(dir / "right");
  const std::string msg = input_error_of([&] { FolderSource src(dir); });
  EXPECT_NE(msg.find("missing right/ folder"), std::string::npos) << msg;
}

TEST(StereoFolderErrors, NoFrames) {
  ScratchDir tmp;
  const fs::path dir = tmp.path() / "seq";
  write_folder(dir, 0, false);
  const std::string msg = input_error_of([&] { FolderSource src(dir); });
  EXPECT_NE(msg.find("no frames"), std::string::npos) << msg;
}

TEST(StereoFolderErrors, LeftRightCountsDiffer) {
  ScratchDir tmp;
  const fs::path dir = tmp.path() / "seq";
  write_folder(dir, 4, false);
  fs::remove(dir / "right" / "000003.png");
  const std::string msg = input_error_of([&] { FolderSource src(dir); });
  EXPECT_NE(msg.find("left/ has 4 images, right/ has 3"), std::string::npos) << msg;
}

TEST(StereoFolderErrors, LeftRightSizesDiffer) {
  ScratchDir tmp;
  const fs::path dir = tmp.path() / "seq";
  write_folder(dir, 2, false);
  ASSERT_TRUE(cv::imwrite((dir / "right" / "000000.png").string(),
                          cv::Mat(kHeight, kWidth + 2, CV_8UC1, cv::Scalar(5))));
  const std::string msg = input_error_of([&] { FolderSource src(dir); });
  EXPECT_NE(msg.find("size mismatch"), std::string::npos) << msg;
  EXPECT_NE(msg.find("37x23"), std::string::npos) << msg;
  EXPECT_NE(msg.find("39x23"), std::string::npos) << msg;
}

TEST(StereoFolderErrors, LaterFrameSizeDiffersFromFirst) {
  ScratchDir tmp;
  const fs::path dir = tmp.path() / "seq";
  write_folder(dir, 3, false);
  const cv::Mat small(kHeight - 4, kWidth, CV_8UC1, cv::Scalar(5));
  ASSERT_TRUE(cv::imwrite((dir / "left" / "000001.png").string(), small));
  ASSERT_TRUE(cv::imwrite((dir / "right" / "000001.png").string(), small));
  FolderSource src(dir);
  ASSERT_TRUE(src.next());
  const std::string msg = input_error_of([&] { src.next(); });
  EXPECT_NE(msg.find("000001.png"), std::string::npos) << msg;
  EXPECT_NE(msg.find("first frame is 37x23"), std::string::npos) << msg;
}

TEST(StereoFolderErrors, CorruptPngMidSequence) {
  ScratchDir tmp;
  const fs::path dir = tmp.path() / "seq";
  const Written w = write_folder(dir, 4, false);
  const fs::path bad = dir / "left" / "000002.png";
  std::ofstream(bad, std::ios::binary | std::ios::trunc) << "\x89PNG garbage, not an image";
  FolderSource src(dir);  // the constructor only checks the first pair
  for (int i = 0; i < 2; ++i) {
    auto f = src.next();
    ASSERT_TRUE(f) << i;
    expect_equal_mats(f->left, w.frames[i].left);
  }
  const std::string msg = input_error_of([&] { src.next(); });
  EXPECT_NE(msg.find(bad.string()), std::string::npos) << msg;
  // The stream moves past the broken frame.
  auto f3 = src.next();
  ASSERT_TRUE(f3);
  EXPECT_EQ(f3->index, 3);
}

// next_pending reads and stamps only; the pixels come from load(), which may run later on
// another thread and out of order, and a broken pair throws from its load, not from the read.
TEST(StereoFolder, PendingFramesDecodeLaterOnAnyThreadAndBreakOnlyInLoad) {
  ScratchDir tmp;
  const fs::path dir = tmp.path() / "seq";
  const Written w = write_folder(dir, 4, false);
  const fs::path bad = dir / "right" / "000002.png";
  std::ofstream(bad, std::ios::binary | std::ios::trunc) << "not a png";
  FolderSource src(dir);
  std::vector<core::PendingFrame> pending;
  while (auto p = src.next_pending()) pending.push_back(std::move(*p));
  ASSERT_EQ(pending.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(pending[i].index, i);
    EXPECT_DOUBLE_EQ(pending[i].time_s, i / src.camera().fps);
  }
  core::StereoFrame f3;
  std::thread([&] { f3 = pending[3].load(); }).join();  // before frame 0, on another thread
  EXPECT_EQ(f3.index, 3);
  expect_equal_mats(f3.left, w.frames[3].left);
  expect_equal_mats(f3.right, w.frames[3].right);
  const core::StereoFrame f0 = pending[0].load();
  expect_equal_mats(f0.left, w.frames[0].left);
  const std::string msg = input_error_of([&] { pending[2].load(); });
  EXPECT_NE(msg.find(bad.string()), std::string::npos) << msg;
}

TEST(StereoFolderErrors, MalformedFramesJsonlLine) {
  ScratchDir tmp;
  const fs::path dir = tmp.path() / "seq";
  write_folder(dir, 3, true);
  const fs::path jsonl = dir / "gt" / "frames.jsonl";
  std::ifstream in(jsonl);
  std::string l1, l2, l3;
  std::getline(in, l1);
  std::getline(in, l2);
  std::getline(in, l3);
  in.close();
  std::ofstream(jsonl, std::ios::trunc) << l1 << "\n" << l2 << "\n{\"frame\": 2, \"alarm\": tru\n";
  const std::string msg = input_error_of([&] { FolderSource src(dir); });
  EXPECT_NE(msg.find("frames.jsonl:3"), std::string::npos) << msg;
}

TEST(TruthLine, RoundTripAndFieldErrors) {
  core::FrameTruth t;
  t.frame = 9;
  t.alarm = true;
  t.obstacles.push_back({3, true, 0.1 + 0.2, 42});
  t.obstacles.push_back({4, false, std::nullopt, 0});
  const std::string line = truth_to_json_line(t);
  EXPECT_EQ(line.find('\n'), std::string::npos);
  EXPECT_EQ(line.rfind("{\"frame\":9,\"alarm\":true,\"obstacles\":[", 0), 0u) << line;
  EXPECT_NE(line.find("\"ttc_s\":null"), std::string::npos) << line;
  const core::FrameTruth back = parse_truth_line(line, "x");
  EXPECT_EQ(back.frame, 9);
  ASSERT_EQ(back.obstacles.size(), 2u);
  EXPECT_EQ(back.obstacles[0].ttc_s, 0.1 + 0.2);  // exact double round trip
  EXPECT_FALSE(back.obstacles[1].ttc_s.has_value());

  EXPECT_NE(input_error_of([] { parse_truth_line("[1,2]", "f:1"); }).find("f:1"),
            std::string::npos);
  EXPECT_NE(input_error_of([] { parse_truth_line(R"({"frame":1,"obstacles":[]})", "f:2"); })
                .find("'alarm'"),
            std::string::npos);
  EXPECT_NE(input_error_of([] {
              parse_truth_line(
                  R"({"frame":1,"alarm":false,"obstacles":[{"id":1,"colliding":true,"ttc_s":"x","pixels":3}]})",
                  "f:3");
            }).find("'ttc_s'"),
            std::string::npos);
}

TEST(FolderWriterErrors, CannotCreateFolder) {
  ScratchDir tmp;
  const fs::path file = tmp.path() / "blocker";
  std::ofstream(file) << "x";
  const std::string msg =
      input_error_of([&] { FolderWriter w(file / "seq", test_camera(), true); });
  EXPECT_NE(msg.find("cannot create folder"), std::string::npos) << msg;
}

}  // namespace
}  // namespace sg::io
