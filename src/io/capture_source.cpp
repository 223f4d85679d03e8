#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <opencv2/imgproc.hpp>

#include "gray.hpp"
#include "sg/core/error.hpp"
#include "sg/io/sources.hpp"

namespace sg::io {
namespace {

cv::VideoCapture open_file(const std::string& path) {
  // FFmpeg's own log lines would break the one-line error a user gets for a broken video; the
  // errors are reported by us. A user's OPENCV_FFMPEG_LOGLEVEL wins (setenv does not overwrite).
  ::setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", 0);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw core::InputError("video not found: " + path);
  }
  cv::VideoCapture capture;
  try {
    capture.open(path, cv::CAP_FFMPEG);
  } catch (const cv::Exception&) {
  }
  if (!capture.isOpened()) {
    throw core::InputError("cannot read video (corrupt or not a video): " + path);
  }
  return capture;
}

cv::VideoCapture open_device(int index) {
  // OpenCV's V4L2 backend waits 10 s per read for a camera that stopped sending; 2 s is plenty to
  // call it stuck (read once per process, before the first capture; a user's setting wins).
  ::setenv("OPENCV_VIDEOIO_V4L_SELECT_TIMEOUT", "2", 0);
  const std::string device = "/dev/video" + std::to_string(index);
  std::error_code ec;
  if (index < 0 || !std::filesystem::exists(device, ec)) {
    throw core::InputError("camera " + std::to_string(index) + " not found (no " + device + ")");
  }
  cv::VideoCapture capture;
  try {
    capture.open(index, cv::CAP_V4L2);
  } catch (const cv::Exception&) {
  }
  if (!capture.isOpened()) {
    throw core::InputError("cannot open camera " + std::to_string(index) + " (" + device +
                           "): busy, not a capture device, or no permission");
  }
  return capture;
}

int declared_frames(cv::VideoCapture& capture) {
  const double n = capture.get(cv::CAP_PROP_FRAME_COUNT);
  return std::isfinite(n) && n > 0 && n < 1e9 ? static_cast<int>(n) : -1;
}

double steady_now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// The capture stamp of the frame just grabbed, s: V4L2's buffer time (CLOCK_MONOTONIC, the
/// steady clock on Linux), or `now_s` when the driver gives none or an implausible one.
double capture_stamp(cv::VideoCapture& capture, double now_s) {
  const double s = capture.get(cv::CAP_PROP_POS_MSEC) / 1000.0;
  return std::isfinite(s) && s > 0.0 && s <= now_s && now_s - s < 5.0 ? s : now_s;
}

/// The two halves of a side-by-side frame (even width).
void split_halves(const cv::Mat& sbs, cv::Mat& left, cv::Mat& right) {
  const int half = sbs.cols / 2;
  left = sbs.colRange(0, half).clone();
  right = sbs.colRange(half, 2 * half).clone();
}

}  // namespace

int LiveFrameClock::index_of(double stamp_s) {
  if (last_ < 0) {
    first_ = stamp_s;
    last_ = 0;
    return 0;
  }
  const long periods = std::lround((stamp_s - first_) / period_s_);
  last_ = static_cast<int>(std::max<long>(last_ + 1L, periods));
  return last_;
}

std::unique_ptr<CaptureSource> CaptureSource::open_videos(const std::string& left,
                                                          const std::string& right,
                                                          const core::Camera& camera) {
  std::vector<Capture> c(2);
  c[0] = {left, open_file(left), -1};
  c[1] = {right, open_file(right), -1};
  return std::unique_ptr<CaptureSource>(new CaptureSource(std::move(c), false, camera));
}

std::unique_ptr<CaptureSource> CaptureSource::open_sbs_video(const std::string& path,
                                                             const core::Camera& camera) {
  std::vector<Capture> c(1);
  c[0] = {path, open_file(path), -1};
  return std::unique_ptr<CaptureSource>(new CaptureSource(std::move(c), false, camera));
}

std::unique_ptr<CaptureSource> CaptureSource::open_cameras(int left, int right,
                                                           const core::Camera& camera) {
  std::vector<Capture> c;
  c.push_back({"/dev/video" + std::to_string(left), open_device(left), -1});
  if (right >= 0) c.push_back({"/dev/video" + std::to_string(right), open_device(right), -1});
  return std::unique_ptr<CaptureSource>(new CaptureSource(std::move(c), true, camera));
}

CaptureSource::CaptureSource(std::vector<Capture> captures, bool live, const core::Camera& camera)
    : captures_(std::move(captures)), live_(live), camera_(camera) {
  for (auto& c : captures_) c.declared_frames = live_ ? -1 : declared_frames(c.capture);
  const double rate = captures_[0].capture.get(cv::CAP_PROP_FPS);
  if (std::isfinite(rate) && rate > 0 && rate < core::kMaxFps) camera_.fps = rate;
  clock_ = LiveFrameClock(camera_.fps);
  if (!live_) {
    frame_count_ = captures_[0].declared_frames;
    if (captures_.size() == 2 && captures_[1].declared_frames >= 0 && frame_count_ >= 0) {
      frame_count_ = std::min(frame_count_, captures_[1].declared_frames);
    }
  }
  if (live_) {
    first_stamp_s_ = grab_newest(first_);
  } else if (!grab(first_)) {
    throw core::InputError("cannot read a frame from " + captures_[0].name +
                           " (empty or corrupt video)");
  }
  cv::Size size = first_[0].size();
  if (captures_.size() == 1) {
    if (size.width % 2 != 0) {
      throw core::InputError("side-by-side input " + captures_[0].name + " has an odd width " +
                             std::to_string(size.width) + "; expected left and right halves");
    }
    size.width /= 2;
  } else {
    detail::check_size(first_[1], size, captures_[1].name, captures_[0].name);
  }
  camera_.width = size.width;
  camera_.height = size.height;
  centre_unknown_principal_point(camera_);
}

bool CaptureSource::grab(std::vector<cv::Mat>& frames) {
  frames.assign(captures_.size(), cv::Mat());
  std::vector<bool> got(captures_.size(), false);
  for (size_t k = 0; k < captures_.size(); ++k) {
    try {
      got[k] = captures_[k].capture.read(frames[k]) && !frames[k].empty();
    } catch (const cv::Exception&) {
      got[k] = false;
    }
  }
  for (size_t k = 0; k < captures_.size(); ++k) {
    if (got[k]) continue;
    // A video that stops well before the length its container states is broken.
    if (captures_[k].declared_frames > 0 && next_index_ + 1 < captures_[k].declared_frames) {
      throw core::InputError(
          "video " + captures_[k].name + " ends after " + std::to_string(next_index_) + " of its " +
          std::to_string(captures_[k].declared_frames) + " frames (truncated or corrupt)");
    }
  }
  if (captures_.size() == 2 && got[0] != got[1]) {
    const size_t ended = got[0] ? 1 : 0;
    std::cerr << "stereoguard: warning: " << captures_[ended].name << " ended after " << next_index_
              << " frames, before " << captures_[1 - ended].name << "; stopping at the shorter\n";
  }
  for (bool g : got) {
    if (!g) return false;
  }
  return true;
}

double CaptureSource::grab_newest(std::vector<cv::Mat>& frames) {
  constexpr int kMaxStale = 16;  // more frames than any driver queues
  auto fail = [](const Capture& c) {
    return core::InputError("camera " + c.name + " gives no image (stopped, unplugged or busy)");
  };
  double stamp = 0.0;
  for (int stale = 0;; ++stale) {
    // grab() only dequeues (both cameras as close together as possible); decoding waits for the
    // frame that is kept.
    for (Capture& c : captures_) {
      bool ok = false;
      try {
        ok = c.capture.grab();
      } catch (const cv::Exception&) {
      }
      if (!ok) throw fail(c);
    }
    const double now = steady_now_s();
    stamp = capture_stamp(captures_[0].capture, now);
    if (stale == kMaxStale || !clock_.stale(stamp, now)) break;
  }
  frames.assign(captures_.size(), cv::Mat());
  for (size_t k = 0; k < captures_.size(); ++k) {
    bool ok = false;
    try {
      ok = captures_[k].capture.retrieve(frames[k]) && !frames[k].empty();
    } catch (const cv::Exception&) {
    }
    if (!ok) throw fail(captures_[k]);
  }
  return stamp;
}

std::optional<core::PendingFrame> CaptureSource::next_pending() {
  std::vector<cv::Mat> frames;
  double stamp = 0.0;
  if (next_index_ == 0) {
    frames = std::move(first_);
    stamp = first_stamp_s_;
  } else if (live_) {
    stamp = grab_newest(frames);
  } else if (!grab(frames)) {
    return std::nullopt;
  }
  // A camera's index counts its frames from the stamps, so a frame lost is a gap.
  const int i = live_ ? clock_.index_of(stamp) : next_index_;
  ++next_index_;
  core::PendingFrame pending;
  pending.index = i;
  pending.time_s = live_ ? stamp - clock_.first_stamp() : i / camera_.fps;
  pending.load = [frames = std::move(frames), i, t = pending.time_s,
                  size = cv::Size(camera_.width, camera_.height), name = captures_[0].name] {
    core::StereoFrame frame;
    frame.index = i;
    frame.time_s = t;
    if (frames.size() == 1) {
      const cv::Mat gray = detail::to_gray8(frames[0], name);
      detail::check_size(gray, cv::Size(size.width * 2, size.height),
                         name + " frame " + std::to_string(i), "the first frame");
      split_halves(gray, frame.left, frame.right);
    } else {
      frame.left = detail::to_gray8(frames[0], name);
      frame.right = detail::to_gray8(frames[1], name);
      detail::check_size(frame.left, size, "left frame " + std::to_string(i), "the first frame");
      detail::check_size(frame.right, size, "right frame " + std::to_string(i), "the first frame");
    }
    return frame;
  };
  return pending;
}

}  // namespace sg::io
