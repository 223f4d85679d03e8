#include "live_view.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <opencv2/highgui.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "sg/core/error.hpp"

namespace sg::apps {
namespace {

const char* const kWindow = "stereoguard";
/// Weight of the newest interval in the smoothed display rate: about the last 10 frames.
constexpr double kRateSmoothing = 0.1;

bool set(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0';
}

}  // namespace

LiveView::LiveView() {
  if (!set("DISPLAY") && !set("WAYLAND_DISPLAY")) {
    throw core::InputError("--show needs a display: neither DISPLAY nor WAYLAND_DISPLAY is set");
  }
  try {
    cv::namedWindow(kWindow, cv::WINDOW_AUTOSIZE);
  } catch (const cv::Exception& e) {
    throw core::InputError("--show cannot open a window: " + e.err);
  }
}

LiveView::~LiveView() {
  try {
    cv::destroyWindow(kWindow);
    cv::waitKey(1);  // lets the window system process the close
  } catch (const cv::Exception&) {
    // Nothing left to show; the run's outputs do not depend on the window.
  }
}

bool LiveView::show(const cv::Mat& overlay, const core::Detection& detection) {
  const auto now = std::chrono::steady_clock::now();
  if (last_shown_) {
    const double ms = std::chrono::duration<double, std::milli>(now - *last_shown_).count();
    interval_ms_ = interval_ms_ > 0 ? interval_ms_ + kRateSmoothing * (ms - interval_ms_) : ms;
  }
  const bool first = !last_shown_;
  last_shown_ = now;

  cv::Mat shown = overlay.clone();
  char text[64];
  if (interval_ms_ > 0) {
    std::snprintf(text, sizeof text, "%.1f fps  latency %.0f ms", 1000.0 / interval_ms_,
                  detection.latency_ms);
  } else {
    std::snprintf(text, sizeof text, "latency %.0f ms", detection.latency_ms);
  }
  constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
  const double scale = std::max(0.4, shown.cols / 1280.0);
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, kFont, scale, 1, &baseline);
  const int pad = 4;
  const cv::Rect strip(0, shown.rows - size.height - baseline - 2 * pad,
                       std::min(shown.cols, size.width + 2 * pad), size.height + baseline + 2 * pad);
  cv::rectangle(shown, strip & cv::Rect(0, 0, shown.cols, shown.rows), cv::Scalar(0, 0, 0),
                cv::FILLED);
  cv::putText(shown, text, cv::Point(pad, shown.rows - baseline - pad), kFont, scale,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  cv::imshow(kWindow, shown);
  const int key = cv::waitKey(1);
  if (key >= 0 && ((key & 0xFF) == 'q' || (key & 0xFF) == 'Q' || (key & 0xFF) == 27)) return false;
  // The window closed by its title bar: shown no more.
  if (!first && cv::getWindowProperty(kWindow, cv::WND_PROP_VISIBLE) < 1) return false;
  return true;
}

}  // namespace sg::apps
