#pragma once
/// Ground-truth file formats: Middlebury .flo and KITTI-style 16-bit disparity PNG, and the
/// discovery of optical-flow pairs with their .flo in a dataset folder.
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace sg::io {

/// Middlebury .flo: "PIEH" tag (float 202021.25), int32 width, height, then float32 (u, v) rows.
/// Values >= 1e9 mean unknown. Returns CV_32FC2. Throws core::InputError on a bad file.
cv::Mat read_flo(const std::filesystem::path& path);
void write_flo(const std::filesystem::path& path, const cv::Mat& flow);

/// 16-bit PNG, value = disparity * 256, 0 = unknown. Returns CV_32F px (0 = unknown).
cv::Mat read_disparity_png(const std::filesystem::path& path);
/// Writes a CV_32F disparity (<= 0 or non-finite = unknown).
void write_disparity_png(const std::filesystem::path& path, const cv::Mat& disparity);

/// Two images and the forward GT flow from the first to the second.
struct FlowGtPair {
  std::string name;  ///< Middlebury NAME, FlyingChairs ID
  std::filesystem::path first, second, gt;
};

/// Pairs found in `dir` and its direct subfolders (each in name order): Middlebury (NAME.flo
/// with NAME1.EXT and NAME2.EXT) and FlyingChairs (ID-gt.flo with ID-img0.EXT and ID-img1.EXT),
/// EXT any image extension (is_image_file). A .flo without its two images is skipped. Throws
/// core::InputError when the folder does not exist or holds no pair.
std::vector<FlowGtPair> find_flow_gt_pairs(const std::filesystem::path& dir);

}  // namespace sg::io
