#pragma once
/// Turns the input flags (--left/--right, --sbs, --kitti, --euroc, --camera, --calib, --focal ...)
/// into a FrameSource. The CLI and the config file fill a SourceSpec; open_source does the rest.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sg/core/source.hpp"

namespace sg::io {

struct SourceSpec {
  std::string left, right;   ///< two videos, two image folders or two glob patterns
  std::string sbs;           ///< one side-by-side video (left half = left image)
  bool sbs_camera = false;   ///< with one camera index: the device gives side-by-side frames
  std::string kitti;         ///< KITTI raw drive folder
  bool kitti_color = false;  ///< image_02/image_03 instead of image_00/image_01
  std::string euroc;         ///< EuRoC mav0 folder (or its parent)
  std::vector<int> camera;   ///< V4L2 device indices: {left, right}, or {index} with sbs_camera
  std::string calib;         ///< calibration file: OpenCV YAML/XML, KITTI calib txt or camera.yaml
  std::optional<double> focal_px, baseline_m, cx, cy;  ///< rectified camera: px, m, px, px
  std::optional<double> input_fps;  ///< rate of an image sequence without timestamps, Hz

  /// True when any input flag above is set (else the caller falls back to --scenario/--input).
  bool any() const;
  /// Short name for messages, e.g. "sbs.mkv" or "euroc ../mav0".
  std::string name() const;
};

/// Opens the one input the spec names. Throws core::InputError for two inputs at once, a missing
/// calibration for an input that needs one, a missing or broken file, or an invalid camera.
std::unique_ptr<core::FrameSource> open_source(const SourceSpec& spec);

}  // namespace sg::io
