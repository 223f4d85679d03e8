#pragma once
/// Ground-truth file formats: Middlebury .flo and KITTI-style 16-bit disparity PNG.
#include <filesystem>
#include <opencv2/core.hpp>

namespace sg::io {

/// Middlebury .flo: "PIEH" tag (float 202021.25), int32 width, height, then float32 (u, v) rows.
/// Values >= 1e9 mean unknown. Returns CV_32FC2. Throws core::InputError on a bad file.
cv::Mat read_flo(const std::filesystem::path& path);
void write_flo(const std::filesystem::path& path, const cv::Mat& flow);

/// 16-bit PNG, value = disparity * 256, 0 = unknown. Returns CV_32F px (0 = unknown).
cv::Mat read_disparity_png(const std::filesystem::path& path);
/// Writes a CV_32F disparity (<= 0 or non-finite = unknown).
void write_disparity_png(const std::filesystem::path& path, const cv::Mat& disparity);

}  // namespace sg::io
