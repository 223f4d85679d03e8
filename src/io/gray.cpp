#include "gray.hpp"

#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sg/core/error.hpp"

namespace sg::io::detail {

cv::Mat to_gray8(const cv::Mat& raw, const std::string& what) {
  if (raw.depth() != CV_8U && raw.depth() != CV_16U) {
    throw core::InputError("unsupported image depth (need 8- or 16-bit): " + what);
  }
  cv::Mat gray;
  switch (raw.channels()) {
    case 1:
      gray = raw;
      break;
    case 2:
      cv::extractChannel(raw, gray, 0);
      break;
    case 3:
      cv::cvtColor(raw, gray, cv::COLOR_BGR2GRAY);
      break;
    case 4:
      cv::cvtColor(raw, gray, cv::COLOR_BGRA2GRAY);
      break;
    default:
      throw core::InputError("unsupported channel count " + std::to_string(raw.channels()) + ": " +
                             what);
  }
  if (gray.depth() == CV_16U) {
    cv::Mat eight;
    gray.convertTo(eight, CV_8U, 1.0 / 257.0);
    return eight;
  }
  return gray;
}

}  // namespace sg::io::detail

namespace sg::io {
namespace {

/// The whole file when it starts with the PNG signature, else empty.
std::vector<std::uint8_t> png_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  char head[8] = {};
  if (!in.read(head, sizeof(head)) || std::memcmp(head, "\x89PNG\r\n\x1a\n", 8) != 0) return {};
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size <= 0) return {};
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
  in.seekg(0);
  if (!in.read(reinterpret_cast<char*>(bytes.data()), size)) return {};
  return bytes;
}

}  // namespace

cv::Mat read_gray(const std::filesystem::path& path) {
  const std::vector<std::uint8_t> bytes = png_bytes(path);
  if (!bytes.empty()) {
    cv::Mat image = decode_gray8_png(bytes);
    if (!image.empty()) return image;
  }
  return read_gray_opencv(path);
}

cv::Mat read_gray_opencv(const std::filesystem::path& path) {
  cv::Mat raw;
  try {
    raw = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception&) {
    raw.release();
  }
  if (raw.empty()) {
    throw core::InputError("cannot read image (missing, corrupt or not an image): " +
                           path.string());
  }
  return detail::to_gray8(raw, path.string());
}

}  // namespace sg::io

namespace sg::io::detail {

std::string size_text(cv::Size s) {
  return std::to_string(s.width) + "x" + std::to_string(s.height);
}

void check_size(const cv::Mat& image, cv::Size expected, const std::string& what,
                const std::string& expected_what) {
  if (image.size() == expected) return;
  throw core::InputError("size mismatch: " + what + " is " + size_text(image.size()) + ", " +
                         expected_what + " is " + size_text(expected));
}

}  // namespace sg::io::detail
