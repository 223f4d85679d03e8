#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "io_test_util.hpp"
#include "sg/io/gt_formats.hpp"

namespace sg::io {
namespace {

namespace fs = std::filesystem;
using testing_util::input_error_of;
using testing_util::ScratchDir;

cv::Mat random_flow(int rows, int cols, uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat flow(rows, cols, CV_32FC2);
  rng.fill(flow, cv::RNG::UNIFORM, -40.0, 40.0);
  return flow;
}

std::string file_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(Flo, WriteReadExact) {
  ScratchDir tmp;
  const fs::path file = tmp.path() / "a.flo";
  cv::Mat flow = random_flow(19, 31, 7);
  flow.at<cv::Vec2f>(0, 0) = cv::Vec2f(1e10f, 1e10f);  // "unknown" passes through unchanged
  write_flo(file, flow);
  EXPECT_EQ(fs::file_size(file), 12u + 19u * 31u * 8u);
  const cv::Mat back = read_flo(file);
  ASSERT_EQ(back.type(), CV_32FC2);
  ASSERT_EQ(back.size(), flow.size());
  EXPECT_EQ(std::memcmp(back.data, flow.data, flow.total() * flow.elemSize()), 0);
}

TEST(Flo, HeaderLayoutIsMiddlebury) {
  ScratchDir tmp;
  const fs::path file = tmp.path() / "a.flo";
  cv::Mat flow(3, 5, CV_32FC2, cv::Scalar(0.5, -2.0));
  write_flo(file, flow);
  const std::string bytes = file_bytes(file);
  ASSERT_GE(bytes.size(), 12u);
  EXPECT_EQ(bytes.substr(0, 4), "PIEH");  // 202021.25f little-endian spells "PIEH"
  const unsigned char* b = reinterpret_cast<const unsigned char*>(bytes.data());
  EXPECT_EQ(b[4] | (b[5] << 8), 5);  // width
  EXPECT_EQ(b[8] | (b[9] << 8), 3);  // height
}

TEST(Flo, NonContinuousInputWritesTheRoi) {
  ScratchDir tmp;
  const fs::path file = tmp.path() / "roi.flo";
  const cv::Mat big = random_flow(21, 33, 11);
  const cv::Mat roi = big(cv::Rect(3, 2, 17, 9));
  ASSERT_FALSE(roi.isContinuous());
  write_flo(file, roi);
  const cv::Mat back = read_flo(file);
  ASSERT_EQ(back.size(), roi.size());
  EXPECT_EQ(cv::norm(back, roi, cv::NORM_INF), 0.0);
}

TEST(Flo, BadHeader) {
  ScratchDir tmp;
  const fs::path file = tmp.path() / "bad.flo";
  std::ofstream(file, std::ios::binary) << "P6\n3 3\n255\nxxxxxxxxxxxxxxxxxxxx";
  const std::string msg = input_error_of([&] { read_flo(file); });
  EXPECT_NE(msg.find("not a .flo file (bad header)"), std::string::npos) << msg;
  EXPECT_NE(msg.find(file.string()), std::string::npos) << msg;
}

TEST(Flo, MissingFile) {
  ScratchDir tmp;
  const fs::path file = tmp.path() / "none.flo";
  const std::string msg = input_error_of([&] { read_flo(file); });
  EXPECT_NE(msg.find(file.string()), std::string::npos) << msg;
}

TEST(Flo, TruncatedData) {
  ScratchDir tmp;
  const fs::path file = tmp.path() / "cut.flo";
  write_flo(file, random_flow(9, 13, 3));
  fs::resize_file(file, fs::file_size(file) - 5);
  const std::string msg = input_error_of([&] { read_flo(file); });
  EXPECT_NE(msg.find("truncated"), std::string::npos) << msg;
  EXPECT_NE(msg.find(file.string()), std::string::npos) << msg;
}

TEST(Flo, AbsurdDimensions) {
  ScratchDir tmp;
  const fs::path file = tmp.path() / "huge.flo";
  write_flo(file, random_flow(2, 2, 3));
  std::string bytes = file_bytes(file);
  bytes[7] = '\x7f';  // width becomes ~2^31
  std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
  const std::string msg = input_error_of([&] { read_flo(file); });
  EXPECT_NE(msg.find("absurd"), std::string::npos) << msg;
}

TEST(DisparityPng, RoundTripWithin1Over256AndUnknownKept) {
  ScratchDir tmp;
  const fs::path file = tmp.path() / "d.png";
  cv::RNG rng(99);
  cv::Mat disp(23, 41, CV_32FC1);
  rng.fill(disp, cv::RNG::UNIFORM, 0.01, 250.0);
  disp.at<float>(0, 0) = 0.0f;
  disp.at<float>(5, 7) = -3.0f;                                  // invalid -> unknown
  disp.at<float>(6, 7) = std::numeric_limits<float>::quiet_NaN();  // unknown
  disp.at<float>(7, 7) = 0.001f;                                // tiny but known
  disp.at<float>(8, 7) = 1000.0f;                               // clamped to 65535/256
  write_disparity_png(file, disp);

  const cv::Mat raw = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(raw.type(), CV_16UC1);
  EXPECT_EQ(raw.at<uint16_t>(2, 3), static_cast<uint16_t>(std::lround(disp.at<float>(2, 3) * 256)));

  const cv::Mat back = read_disparity_png(file);
  ASSERT_EQ(back.type(), CV_32FC1);
  ASSERT_EQ(back.size(), disp.size());
  EXPECT_EQ(back.at<float>(0, 0), 0.0f);
  EXPECT_EQ(back.at<float>(5, 7), 0.0f);
  EXPECT_EQ(back.at<float>(6, 7), 0.0f);
  EXPECT_GT(back.at<float>(7, 7), 0.0f);
  EXPECT_FLOAT_EQ(back.at<float>(8, 7), 65535.0f / 256.0f);
  for (int y = 0; y < disp.rows; ++y) {
    for (int x = 0; x < disp.cols; ++x) {
      const float d = disp.at<float>(y, x);
      if (!(d > 0.0f) || d > 255.0f) continue;
      EXPECT_LE(std::abs(back.at<float>(y, x) - d), 1.0f / 256.0f) << y << "," << x;
    }
  }
}

// Found by fuzz_flo (timeout): a 19-byte file whose header claims 12159x16496 made the reader
// allocate 1.6 GB before noticing the data was missing. The size check now comes first.
TEST(Flo, LargeHeaderOnASmallFileIsRejectedBeforeAllocating) {
  ScratchDir tmp;
  const fs::path file = tmp.path() / "fuzz.flo";
  const unsigned char bytes[] = {'P',  'I',  'E',  'H',  0x7f, 0x2f, 0x00, 0x00, 0x70, 0x40,
                                 0x00, 0x00, 0x50, 0x49, 0x6a, 0x82, 0x48, 0x03, 0x00};
  std::ofstream(file, std::ios::binary).write(reinterpret_cast<const char*>(bytes), sizeof bytes);
  const std::string msg = input_error_of([&] { read_flo(file); });
  EXPECT_NE(msg.find("12159x16496 needs 1604598924 bytes, the file has 19"), std::string::npos)
      << msg;
}

// Found by fuzz_disparity_png: cv::imread decodes by content, so any format OpenCV knows (TIFF,
// JPEG 2000, EXR...) was decoded from a file the user gave as a disparity PNG, and a 16-bit TIFF
// was accepted as one.
TEST(DisparityPng, RejectsAnotherFormatNamedPng) {
  if (!cv::haveImageWriter(".tiff")) GTEST_SKIP() << "OpenCV without TIFF";
  ScratchDir tmp;
  const fs::path tiff = tmp.path() / "d.tiff";
  ASSERT_TRUE(cv::imwrite(tiff.string(), cv::Mat(5, 7, CV_16UC1, cv::Scalar(300))));
  const fs::path file = tmp.path() / "d.png";
  fs::rename(tiff, file);
  const std::string msg = input_error_of([&] { read_disparity_png(file); });
  EXPECT_NE(msg.find("not a PNG file"), std::string::npos) << msg;
  EXPECT_NE(msg.find(file.string()), std::string::npos) << msg;
}

TEST(DisparityPng, RejectsEightBitPng) {
  ScratchDir tmp;
  const fs::path file = tmp.path() / "d8.png";
  ASSERT_TRUE(cv::imwrite(file.string(), cv::Mat(5, 7, CV_8UC1, cv::Scalar(3))));
  const std::string msg = input_error_of([&] { read_disparity_png(file); });
  EXPECT_NE(msg.find("16-bit single channel"), std::string::npos) << msg;
  EXPECT_NE(msg.find(file.string()), std::string::npos) << msg;
}

TEST(DisparityPng, MissingFile) {
  ScratchDir tmp;
  const fs::path file = tmp.path() / "none.png";
  const std::string msg = input_error_of([&] { read_disparity_png(file); });
  EXPECT_NE(msg.find(file.string()), std::string::npos) << msg;
}

TEST(FlowGtPairs, FindsMiddleburyAndFlyingChairsNamesInTheFolderAndItsSubfolders) {
  ScratchDir tmp;
  const auto touch = [](const fs::path& p) { std::ofstream(p) << "x"; };
  fs::create_directories(tmp.path() / "RubberWhale");
  for (const char* f : {"RubberWhale1.png", "RubberWhale2.png", "RubberWhale.flo"})
    touch(tmp.path() / "RubberWhale" / f);
  for (const char* f : {"0000002-img0.ppm", "0000002-img1.ppm", "0000002-gt.flo",
                        "0000001-img0.ppm", "0000001-img1.ppm", "0000001-gt.flo",
                        "lonely.flo", "0000003-img0.ppm", "0000003-gt.flo", "notes.txt"})
    touch(tmp.path() / f);
  const std::vector<FlowGtPair> pairs = find_flow_gt_pairs(tmp.path());
  // The folder's own pairs in name order, then the subfolder's; .flo files without both images
  // (lonely, 0000003) are left out.
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[0].name, "0000001");
  EXPECT_EQ(pairs[0].first.filename(), "0000001-img0.ppm");
  EXPECT_EQ(pairs[0].second.filename(), "0000001-img1.ppm");
  EXPECT_EQ(pairs[0].gt.filename(), "0000001-gt.flo");
  EXPECT_EQ(pairs[1].name, "0000002");
  EXPECT_EQ(pairs[2].name, "RubberWhale");
  EXPECT_EQ(pairs[2].first.filename(), "RubberWhale1.png");
  EXPECT_EQ(pairs[2].second.filename(), "RubberWhale2.png");
}

TEST(FlowGtPairs, AMissingOrEmptyFolderIsAnInputError) {
  ScratchDir tmp;
  EXPECT_NE(input_error_of([&] { find_flow_gt_pairs(tmp.path() / "nowhere"); }).find("nowhere"),
            std::string::npos);
  EXPECT_NE(input_error_of([&] { find_flow_gt_pairs(tmp.path()); }).find("no pair found"),
            std::string::npos);
}

}  // namespace
}  // namespace sg::io
