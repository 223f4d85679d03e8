#pragma once
/// Overlay video: the left image, danger pixels tinted red, obstacle boxes labelled with distance
/// and TTC, region signals along the top, severity and steering hint.
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "sg/core/detection.hpp"
#include "sg/core/frame.hpp"

namespace sg::io {

/// Draws the overlay of one frame: CV_8UC3 BGR, size of the left image. Danger pixels
/// (detection.danger == 255) are blended 50% with red; obstacle boxes are red with a label
/// "4.2 m  TTC 1.3 s"; the top bar has one cell per region (red = fired, green = not) and a row
/// "frame N  <severity>  <steering hint>" (STOP, <- LEFT, STRAIGHT, RIGHT ->).
cv::Mat draw_overlay(const core::StereoFrame& frame, const core::Detection& detection);

class OverlayWriter {
 public:
  /// Opens an MP4 (mp4v) video; throws core::InputError when it cannot be created.
  OverlayWriter(const std::filesystem::path& path, cv::Size size, double fps);
  /// Draws and appends one overlay frame; throws core::InputError after close().
  void write(const core::StereoFrame& frame, const core::Detection& detection);
  /// Appends an overlay already drawn by draw_overlay (CV_8UC3); throws core::InputError after
  /// close().
  void write(const cv::Mat& overlay);
  int frames_written() const { return frames_; }
  /// Finalises the file so that it plays (also done by the destructor).
  void close();

 private:
  cv::VideoWriter writer_;
  std::filesystem::path path_;
  cv::Size size_;  ///< frame size of the video; overlays of another size are resized to it
  int frames_ = 0;
};

}  // namespace sg::io
