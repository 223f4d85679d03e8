// The gray PNG fast path against cv::imread: the same pixels on every filter and compression
// setting libpng writes, a fallback for every PNG it declines, and corrupt files refused.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sg/io/gray_image.hpp"

namespace sg::io {
namespace {

namespace fs = std::filesystem;

std::vector<std::uint8_t> encode(const cv::Mat& image, std::vector<int> params = {}) {
  std::vector<std::uint8_t> bytes;
  EXPECT_TRUE(cv::imencode(".png", image, bytes, params));
  return bytes;
}

bool same(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

/// Images whose rows make libpng's adaptive filtering pick each of the five filters.
std::vector<cv::Mat> test_images() {
  std::vector<cv::Mat> out;
  cv::RNG rng(7);
  for (const cv::Size size : {cv::Size(1, 1), cv::Size(7, 3), cv::Size(161, 121), cv::Size(752, 480)}) {
    cv::Mat noise(size, CV_8UC1), ramp(size, CV_8UC1), mixed(size, CV_8UC1);
    rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
    for (int y = 0; y < size.height; ++y)
      for (int x = 0; x < size.width; ++x) {
        ramp.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(x * 3 + y * 5);
        // Smooth, noisy, flat and step regions by rows.
        const int band = (y / 4) % 4;
        mixed.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(
            band == 0 ? x + y : band == 1 ? rng.uniform(0, 256) : band == 2 ? 128 : (x / 9) * 40);
      }
    cv::Mat blurred;
    cv::GaussianBlur(noise, blurred, cv::Size(5, 5), 1.5);
    out.insert(out.end(), {noise, ramp, mixed, blurred});
  }
  return out;
}

TEST(PngGray, DecodesEveryFilterAndCompressionLikeOpencv) {
  int checked = 0;
  for (const cv::Mat& image : test_images())
    for (int level : {0, 1, 6, 9})
      for (int strategy : {cv::IMWRITE_PNG_STRATEGY_DEFAULT, cv::IMWRITE_PNG_STRATEGY_FILTERED,
                           cv::IMWRITE_PNG_STRATEGY_RLE, cv::IMWRITE_PNG_STRATEGY_FIXED}) {
        const auto bytes =
            encode(image, {cv::IMWRITE_PNG_COMPRESSION, level, cv::IMWRITE_PNG_STRATEGY, strategy});
        const cv::Mat fast = decode_gray8_png(bytes);
        ASSERT_FALSE(fast.empty()) << image.size() << " level " << level;
        EXPECT_TRUE(same(fast, cv::imdecode(bytes, cv::IMREAD_UNCHANGED)))
            << image.size() << " level " << level << " strategy " << strategy;
        EXPECT_TRUE(same(fast, image));
        ++checked;
      }
  EXPECT_EQ(checked, 16 * 16);
}

TEST(PngGray, DeclinesWhatItDoesNotDecodeAndReadGrayFallsBack) {
  const cv::Mat gray = test_images()[5];
  cv::Mat colour, deep;
  cv::cvtColor(gray, colour, cv::COLOR_GRAY2BGR);
  colour.col(3).setTo(cv::Scalar(10, 200, 30));
  gray.convertTo(deep, CV_16U, 257.0);
  const fs::path dir = fs::path(::testing::TempDir()) / "sg_png_gray";
  fs::create_directories(dir);
  for (const auto& [name, image] : {std::pair{"colour", colour}, std::pair{"deep", deep}}) {
    const auto bytes = encode(image);
    EXPECT_TRUE(decode_gray8_png(bytes).empty()) << name;
    const fs::path path = dir / (std::string(name) + ".png");
    cv::imwrite(path.string(), image);
    EXPECT_TRUE(same(read_gray(path), read_gray_opencv(path))) << name;
  }
  // A PNG that is gray but carries a chunk that could change its pixels (here gAMA).
  auto bytes = encode(gray);
  const std::uint8_t gama[] = {0, 0, 0, 4, 'g', 'A', 'M', 'A', 0, 0, 0xb1, 0x8f,
                               0x0b, 0xfc, 0x61, 0x05};  // gamma 1/2.2, its CRC
  bytes.insert(bytes.begin() + 33, std::begin(gama), std::end(gama));  // after IHDR
  EXPECT_TRUE(decode_gray8_png(bytes).empty());
  EXPECT_FALSE(cv::imdecode(bytes, cv::IMREAD_UNCHANGED).empty());  // a valid PNG still
  // Not a PNG at all, and a JPEG read through read_gray.
  EXPECT_TRUE(decode_gray8_png({1, 2, 3}).empty());
  const fs::path jpeg = dir / "frame.jpg";
  cv::imwrite(jpeg.string(), gray);
  EXPECT_TRUE(same(read_gray(jpeg), read_gray_opencv(jpeg)));
}

TEST(PngGray, CorruptFilesAreDeclinedAndReadGrayReportsThem) {
  const auto good = encode(test_images()[6]);
  ASSERT_FALSE(decode_gray8_png(good).empty());
  // A flipped bit in the pixel data (the IDAT CRC no longer matches) and a truncated file: both
  // keep the signature, so only the checks inside the decoder can refuse them.
  auto flipped = good;
  flipped[good.size() / 2] ^= 0x10;
  EXPECT_TRUE(decode_gray8_png(flipped).empty());
  const std::vector<std::uint8_t> truncated(good.begin(), good.begin() + good.size() / 2);
  EXPECT_TRUE(decode_gray8_png(truncated).empty());
  const fs::path path = fs::path(::testing::TempDir()) / "sg_png_truncated.png";
  {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(truncated.data()),
              static_cast<std::streamsize>(truncated.size()));
  }
  EXPECT_ANY_THROW(read_gray(path));
  EXPECT_ANY_THROW(read_gray(fs::path(::testing::TempDir()) / "sg_no_such_image.png"));
}

TEST(PngGrayData, EurocFramesDecodeLikeOpencv) {
  const fs::path dir = fs::path(SG_SHARED_DIR) / "data" / "euroc_v1_01_micro" / "mav0" / "cam0" / "data";
  if (!fs::is_directory(dir)) GTEST_SKIP() << "no EuRoC clip at " << dir;
  int fast = 0, checked = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() != ".png" || checked >= 20) continue;
    std::ifstream in(entry.path(), std::ios::binary);
    const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), {});
    fast += decode_gray8_png(bytes).empty() ? 0 : 1;
    EXPECT_TRUE(same(read_gray(entry.path()), read_gray_opencv(entry.path()))) << entry.path();
    ++checked;
  }
  EXPECT_GT(checked, 0);
  EXPECT_EQ(fast, checked);  // the clip's frames are 8-bit gray PNGs: all take the fast path
}

}  // namespace
}  // namespace sg::io
