#pragma once
/// `run --show`: a window (OpenCV highgui) showing each detection's overlay (io::draw_overlay) as
/// it is delivered, with the display rate and the frame's latency drawn along its bottom.
#include <chrono>
#include <optional>
#include <opencv2/core.hpp>


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
  /// and the frame's `latency_ms`, and handles the window's events. Returns false when the user
  /// asked to stop: q or Esc pressed, or the window closed. Call it, poll and the constructor and
  /// destructor on one thread (the window toolkit's: run_command keeps it on the main thread).
  bool show(const cv::Mat& overlay, double latency_ms);
  /// Handles the window's events for up to `wait_ms` without a new frame; false as show's.
  bool poll(int wait_ms);

 private:
  std::optional<std::chrono::steady_clock::time_point> last_shown_;
  int frames_shown_ = 0;
  double interval_ms_ = 0.0;  ///< smoothed time between two frames shown, ms (0 before two)
};

}  // namespace sg::apps
