#include "live_view.hpp"

#include <netdb.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cstddef>
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

/// True when the X server of `display` ("[host]:N[.screen]") accepts a connection: its local
/// socket /tmp/.X11-unix/XN (or the abstract one of that name), or TCP port 6000 + N on `host`.
bool x_server_reachable(const std::string& display) {
  const auto colon = display.rfind(':');
  if (colon == std::string::npos) return false;
  const std::string host = display.substr(0, colon);
  const std::string number = display.substr(colon + 1, display.find('.', colon) - colon - 1);
  if (number.empty() || number.find_first_not_of("0123456789") != std::string::npos) return false;
  auto connects = [](int fd, const sockaddr* address, socklen_t length) {
    const bool ok = fd >= 0 && connect(fd, address, length) == 0;
    if (fd >= 0) close(fd);
    return ok;
  };
  if (host.empty() || host == "unix") {
    const std::string path = "/tmp/.X11-unix/X" + number;
    for (const bool abstract : {false, true}) {
      sockaddr_un address{};
      address.sun_family = AF_UNIX;
      const size_t offset = abstract ? 1 : 0;  // abstract names start with a NUL byte
      path.copy(address.sun_path + offset, sizeof address.sun_path - 1 - offset);
      const auto length =
          static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + offset + path.size());
      if (connects(socket(AF_UNIX, SOCK_STREAM, 0), reinterpret_cast<sockaddr*>(&address),
                   length)) {
        return true;
      }
    }
    return false;
  }
  addrinfo hints{};
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (getaddrinfo(host.c_str(), std::to_string(6000 + std::stoi(number)).c_str(), &hints,
                  &found) != 0) {
    return false;
  }
  bool ok = false;
  for (addrinfo* a = found; a && !ok; a = a->ai_next)
    ok = connects(socket(a->ai_family, a->ai_socktype, a->ai_protocol), a->ai_addr, a->ai_addrlen);
  freeaddrinfo(found);
  return ok;
}

}  // namespace

LiveView::LiveView() {
  // OpenCV's window toolkit here (Qt, xcb platform) aborts the process when it cannot reach the
  // X server, so the server is checked first. Under Wayland, XWayland provides DISPLAY.
  if (!set("DISPLAY")) {
    throw core::InputError(set("WAYLAND_DISPLAY")
                               ? "--show needs an X display (XWayland): DISPLAY is not set"
                               : "--show needs a display: neither DISPLAY nor WAYLAND_DISPLAY "
                                 "is set");
  }
  const std::string display = std::getenv("DISPLAY");
  if (!x_server_reachable(display)) {
    throw core::InputError("--show cannot reach the X display " + display);
  }
  try {
    // No toolbar nor status bar (Qt): the window is the picture, sized to it on the first frame;
    // the user may resize it, the picture keeps its aspect ratio.
    cv::namedWindow(kWindow, cv::WINDOW_NORMAL | cv::WINDOW_KEEPRATIO | cv::WINDOW_GUI_NORMAL);
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

bool LiveView::show(const cv::Mat& overlay, double latency_ms) {
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
                  latency_ms);
  } else {
    std::snprintf(text, sizeof text, "latency %.0f ms", latency_ms);
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
  if (first) cv::resizeWindow(kWindow, shown.size());
  cv::imshow(kWindow, shown);
  ++frames_shown_;
  return poll(1);
}

bool LiveView::poll(int wait_ms) {
  const int key = cv::waitKey(wait_ms);
  if (key >= 0 && ((key & 0xFF) == 'q' || (key & 0xFF) == 'Q' || (key & 0xFF) == 27)) return false;
  // The window closed by its title bar: shown no more.
  if (frames_shown_ > 1 && cv::getWindowProperty(kWindow, cv::WND_PROP_VISIBLE) < 1) return false;
  return true;
}

}  // namespace sg::apps
