#pragma once
/// Image files as 8-bit gray, the form every stereoguard input takes.
#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <vector>

namespace sg::io {

/// An image file as 8-bit gray (CV_8UC1): 1 to 4 channels (colour by cv::cvtColor's weights),
/// 8 or 16 bits (16-bit scaled by 1/257). An 8-bit gray PNG is decoded by decode_gray8_png,
/// anything else as read_gray_opencv does; the pixels are the same either way. Throws
/// core::InputError naming the file when it is missing, corrupt or of another depth.
cv::Mat read_gray(const std::filesystem::path& path);

/// The reference of read_gray: cv::imread (IMREAD_UNCHANGED), then the same conversion to gray.
cv::Mat read_gray_opencv(const std::filesystem::path& path);

/// The image of a PNG file held in `bytes` when it is 8-bit grayscale, non-interlaced, has valid
/// chunk CRCs and carries no chunk that changes its pixels (only IHDR, IDAT, IEND and text,
/// time and physical-size chunks); CV_8UC1. Otherwise an empty Mat: the caller decodes it
/// another way (which also reports a corrupt file). Inflated by libdeflate, the row filters (PNG
/// specification, section 9) undone here; its speed against cv::imread is measured by
/// bench/bench_decode.cpp (docs/performance.md).
cv::Mat decode_gray8_png(const std::vector<std::uint8_t>& bytes);

}  // namespace sg::io
