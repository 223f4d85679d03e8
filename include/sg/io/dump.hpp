#pragma once
/// `--dump DIR`: per-frame PNGs of the colour-mapped disparity, the colour-coded optical flow and
/// the danger mask, named by frame index (disparity_000042.png, flow_000042.png,
/// danger_000042.png).
#include <filesystem>
#include <string>

#include "sg/core/detection.hpp"

namespace sg::io {

/// BGR picture of a disparity map (CV_32F, px, invalid < 0): 0 .. max_disparity_px mapped
/// through the Turbo colour map (far = blue, near = red), larger values clamped, invalid black.
cv::Mat colorize_disparity(const cv::Mat& disparity, double max_disparity_px);

/// BGR picture of a flow field (CV_32FC2, px) in the Middlebury colour-wheel code (Baker et al.,
/// "A Database and Evaluation Methodology for Optical Flow"): hue = direction (right red, down
/// yellow-green, left cyan, up blue-violet), saturation = magnitude / max_radius_px (zero flow
/// white, larger than max_radius_px darkened), non-finite vectors black. max_radius_px <= 0 uses
/// the largest finite magnitude of the field (at least 1 px), as the Middlebury tool does.
cv::Mat colorize_flow(const cv::Mat& flow, double max_radius_px = 0.0);

/// Largest finite flow magnitude (px, at least 1) over the pixels where `mask` (CV_8U, same size,
/// may be empty = all pixels) is non-zero: the colour scale of colorize_flow.
double flow_color_scale(const cv::Mat& flow, const cv::Mat& mask = cv::Mat());

class DumpWriter {
 public:
  /// Creates `dir` (and its parents) when missing. Throws core::InputError naming --dump when it
  /// is a file or cannot be created. max_disparity_px sets the disparity colour scale.
  DumpWriter(const std::filesystem::path& dir, double max_disparity_px);
  /// Writes the maps of detection `d` (its danger mask, and its disparity and flow when present)
  /// as PNGs named by d.frame. The flow colour scale is the largest flow magnitude among pixels
  /// with a valid disparity: textureless areas (sky, blank walls) give meaningless flow that would
  /// otherwise wash out every other colour. Throws core::InputError when a file cannot be written.
  void write(const core::Detection& d);
  /// Path of the `kind` ("disparity", "flow", "danger") PNG of `frame`.
  std::filesystem::path path(const std::string& kind, int frame) const;

 private:
  void write_png(const std::filesystem::path& file, const cv::Mat& image) const;

  std::filesystem::path dir_;
  double max_disparity_px_;
};

}  // namespace sg::io
