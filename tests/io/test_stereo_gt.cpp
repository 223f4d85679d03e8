#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "io_test_util.hpp"
#include "sg/io/stereo_gt.hpp"

namespace sg::io {
namespace {

using testing_util::input_error_of;
using testing_util::ScratchDir;

TEST(StereoGt, PfmRoundTripKeepsRowOrder) {
  ScratchDir dir;
  cv::Mat d(3, 4, CV_32F);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x) d.at<float>(y, x) = 1.5f + 10.0f * y + x;
  write_pfm(dir.path() / "d.pfm", d);
  const cv::Mat back = read_pfm(dir.path() / "d.pfm");
  ASSERT_EQ(back.size(), d.size());
  EXPECT_EQ(cv::norm(back, d, cv::NORM_INF), 0.0);
}

TEST(StereoGt, PfmBigEndianBottomUpAndInfinityIsUnknown) {
  ScratchDir dir;
  // Hand-made 2x2 big-endian PFM: rows stored bottom first.
  auto be = [](float v) {
    unsigned char b[4];
    std::memcpy(b, &v, 4);
    return std::string{static_cast<char>(b[3]), static_cast<char>(b[2]), static_cast<char>(b[1]),
                       static_cast<char>(b[0])};
  };
  std::ofstream(dir.path() / "be.pfm", std::ios::binary)
      << "Pf\n2 2\n1.0\n"
      << be(3.0f) << be(4.0f) << be(1.0f) << be(std::numeric_limits<float>::infinity());
  const cv::Mat m = read_pfm(dir.path() / "be.pfm");
  EXPECT_EQ(m.at<float>(0, 0), 1.0f);  // top row was stored last
  EXPECT_EQ(m.at<float>(0, 1), 0.0f);  // inf = unknown
  EXPECT_EQ(m.at<float>(1, 0), 3.0f);
  EXPECT_EQ(m.at<float>(1, 1), 4.0f);
}

TEST(StereoGt, BadPfmIsAnInputError) {
  ScratchDir dir;
  std::ofstream(dir.path() / "x.pfm") << "PF\n2 2\n-1\n";
  EXPECT_NE(input_error_of([&] { read_pfm(dir.path() / "x.pfm"); }).find("PFM"), std::string::npos);
  std::ofstream(dir.path() / "t.pfm", std::ios::binary) << "Pf\n2 2\n-1\nabc";
  EXPECT_NE(input_error_of([&] { read_pfm(dir.path() / "t.pfm"); }).find("truncated"),
            std::string::npos);
}

TEST(StereoGt, MiddleburyPngIsDividedByItsScale) {
  ScratchDir dir;
  cv::Mat v(2, 2, CV_8U);
  v.at<uchar>(0, 0) = 0;
  v.at<uchar>(0, 1) = 64;
  v.at<uchar>(1, 0) = 100;
  v.at<uchar>(1, 1) = 255;
  cv::imwrite((dir.path() / "disp2.png").string(), v);
  const cv::Mat d = read_stereo_gt(dir.path() / "disp2.png", 4.0);
  EXPECT_EQ(d.at<float>(0, 0), 0.0f);
  EXPECT_EQ(d.at<float>(0, 1), 16.0f);
  EXPECT_EQ(d.at<float>(1, 0), 25.0f);
  EXPECT_EQ(d.at<float>(1, 1), 63.75f);
  EXPECT_NE(input_error_of([&] { read_stereo_gt(dir.path() / "disp2.png", 0); }).find("--gt-scale"),
            std::string::npos);
}

TEST(StereoGt, PgmBinaryAndAsciiWithACommentAreRead) {
  ScratchDir dir;
  // Binary 3x1 with a comment in the header; ASCII 2x2 across lines.
  std::ofstream(dir.path() / "bin.pgm", std::ios::binary) << "P5\n# Middlebury\n3 1\n255\n"
                                                          << std::string("\x00\x08\xff", 3);
  const cv::Mat b = read_stereo_gt(dir.path() / "bin.pgm", 8.0);
  ASSERT_EQ(b.size(), cv::Size(3, 1));
  EXPECT_EQ(b.at<float>(0, 0), 0.0f);
  EXPECT_EQ(b.at<float>(0, 1), 1.0f);
  EXPECT_EQ(b.at<float>(0, 2), 255.0f / 8);
  std::ofstream(dir.path() / "ascii.pgm") << "P2 2 2 200\n4 8\n12\n200\n";
  const cv::Mat a = read_stereo_gt(dir.path() / "ascii.pgm", 4.0);
  ASSERT_EQ(a.size(), cv::Size(2, 2));
  EXPECT_EQ(a.at<float>(0, 1), 2.0f);
  EXPECT_EQ(a.at<float>(1, 0), 3.0f);
  EXPECT_EQ(a.at<float>(1, 1), 50.0f);
}

TEST(StereoGt, KittiPngIsDividedBy256) {
  ScratchDir dir;
  cv::Mat v(1, 2, CV_16U);
  v.at<std::uint16_t>(0, 0) = 0;
  v.at<std::uint16_t>(0, 1) = 256 * 30 + 128;
  cv::imwrite((dir.path() / "k.png").string(), v);
  const cv::Mat d = read_stereo_gt(dir.path() / "k.png", 0);
  EXPECT_EQ(d.at<float>(0, 0), 0.0f);
  EXPECT_EQ(d.at<float>(0, 1), 30.5f);
}

TEST(StereoGt, FindsMiddleburyScenesWithDatasetsXmlScalesAndKitti) {
  ScratchDir dir;
  const cv::Mat img(4, 4, CV_8U, cv::Scalar(1));
  for (const char* scene : {"cones", "tsukuba"}) {
    std::filesystem::create_directories(dir.path() / scene);
    for (const char* f : {"im2.png", "im6.png", "disp2.png"})
      cv::imwrite((dir.path() / scene / f).string(), img);
  }
  std::ofstream(dir.path() / "datasets.xml")
      << "<?xml version=\"1.0\"?>\n<opencv_storage>\n<datasets>\n\tcones \"4\" \"0\"\n"
      << "\ttsukuba \"16\" \"0\"\n</datasets>\n</opencv_storage>\n";
  std::filesystem::create_directories(dir.path() / "kitti");
  for (const char* sub : {"image_2", "image_3", "disp_noc_0"}) {
    std::filesystem::create_directories(dir.path() / "kitti" / sub);
    cv::imwrite((dir.path() / "kitti" / sub / "000000_10.png").string(), img);
  }
  const auto pairs = find_stereo_gt_pairs(dir.path(), 0);
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[0].name, "000000_10");
  EXPECT_EQ(pairs[1].name, "cones");
  EXPECT_EQ(pairs[1].scale, 4.0);
  EXPECT_EQ(pairs[2].name, "tsukuba");
  EXPECT_EQ(pairs[2].scale, 16.0);
  EXPECT_EQ(pairs[2].left.filename(), "im2.png");
  EXPECT_EQ(pairs[2].right.filename(), "im6.png");
}

TEST(StereoGt, EmptyOrMissingFolderIsAnInputError) {
  ScratchDir dir;
  EXPECT_NE(input_error_of([&] { find_stereo_gt_pairs(dir.path(), 0); }).find("no stereo pair"),
            std::string::npos);
  EXPECT_NE(
      input_error_of([&] { find_stereo_gt_pairs(dir.path() / "nope", 0); }).find("not a folder"),
      std::string::npos);
}

}  // namespace
}  // namespace sg::io
