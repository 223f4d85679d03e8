#include "gray.hpp"

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

cv::Mat read_gray(const std::filesystem::path& path) {
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
  return to_gray8(raw, path.string());
}

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
