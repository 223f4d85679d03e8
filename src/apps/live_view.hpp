#pragma once
/// `run --show`: a window (OpenCV highgui) showing each detection's overlay (io::draw_overlay) as
/// it is delivered, with the display rate and the frame's latency drawn along its bottom.
#include <chrono>
#include <optional>
#include <opencv2/core.hpp>

#include "sg/core/detection.hpp"

namespace sg::apps {

class LiveView {
 public:
  /// Opens the window. Throws core::InputError naming --show when there is no display (neither
  /// DISPLAY nor WAYLAND_DISPLAY set) or the window cannot be created.
  LiveView();
  /// Closes the window.
  ~LiveView();
  LiveView(const LiveView&) = delete;
  LiveView& operator=(const LiveView&) = delete;

  /// Shows `overlay` (CV_8UC3, as drawn by io::draw_overlay; not modified) with the display rate
  /// and `detection.latency_ms`, and handles the window's events. Returns false when the user
  /// asked to stop: q or Esc pressed, or the window closed.
  bool show(const cv::Mat& overlay, const core::Detection& detection);

 private:
  std::optional<std::chrono::steady_clock::time_point> last_shown_;
  double interval_ms_ = 0.0;  ///< smoothed time between two frames shown, ms (0 before two)
};

}  // namespace sg::apps
