#pragma once
/// Stereo ground truth (DESIGN 6, eval): disparity readers for the usual benchmark formats and the
/// discovery of left/right/GT triples in a dataset folder.
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace sg::io {

/// PFM (Middlebury 2014, SceneFlow): "Pf" header, width height, scale (< 0 little-endian), float32
/// rows bottom to top. Returns CV_32F px in top-to-bottom order; infinities and values <= 0 become
/// 0 (unknown). Throws core::InputError on a bad file, including one shorter than its header says
/// (checked before allocating).
cv::Mat read_pfm(const std::filesystem::path& path);
/// Writes a CV_32F map as little-endian PFM (for tests and tools).
void write_pfm(const std::filesystem::path& path, const cv::Mat& disparity);

/// Middlebury 2001-2006 8-bit PNG: disparity = value / scale, 0 = unknown. scale > 0.
/// Returns CV_32F px (0 = unknown). Throws core::InputError on a bad file or a 16-bit PNG.
cv::Mat read_middlebury_png(const std::filesystem::path& path, double scale);

/// Any GT disparity by its file: .pfm -> read_pfm; 16-bit PNG -> KITTI (value / 256,
/// read_disparity_png); 8-bit PNG -> read_middlebury_png(scale), which needs scale > 0 (else
/// InputError naming the file and asking for --gt-scale). Returns CV_32F px, 0 = unknown.
cv::Mat read_stereo_gt(const std::filesystem::path& path, double scale);

/// One rectified pair with its GT disparity for the left image.
struct StereoGtPair {
  std::string name;  ///< scene name (folder or file stem)
  std::filesystem::path left, right, gt;
  double scale = 0;  ///< for 8-bit PNG GT: disparity = value / scale; 0 = n/a
};

/// Pairs found in `dir` and its subfolders (one level), sorted by name:
/// * Middlebury 2001/2003: im2.png, im6.png, disp2.png; the scale comes from datasets.xml in the
///   folder or its parent (OpenCV's `name "scale" "unknown"` lines), else `scale` (0 = unknown);
/// * Middlebury 2005/2006: view1.png, view5.png, disp1.png (scale as above);
/// * Middlebury 2014: im0.png, im1.png, disp0GT.pfm or disp0.pfm;
/// * KITTI 2012/2015: image_0|image_2/NAME_10.png, image_1|image_3/NAME_10.png,
///   disp_noc|disp_noc_0/NAME_10.png (16-bit).
/// Throws core::InputError when the folder does not exist or holds no pair, or when a
/// datasets.xml scale line has a scale that is not a number > 0.
std::vector<StereoGtPair> find_stereo_gt_pairs(const std::filesystem::path& dir, double scale);

}  // namespace sg::io
