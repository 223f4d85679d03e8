#include "sg/io/overlay.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "sg/core/error.hpp"

namespace sg::io {
namespace {

const cv::Scalar kRed(0, 0, 255);
const cv::Scalar kGreen(0, 160, 0);
const cv::Scalar kYellow(0, 220, 255);
const cv::Scalar kWhite(255, 255, 255);
const cv::Scalar kBlack(0, 0, 0);
constexpr double kTintAlpha = 0.5;  ///< weight of red over a danger pixel
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

const char* steering_text(core::Steering s) {
  switch (s) {
    case core::Steering::kStop: return "STOP";
    case core::Steering::kLeft: return "<- LEFT";
    case core::Steering::kStraight: return "STRAIGHT";
    case core::Steering::kRight: return "RIGHT ->";
  }
  return "?";
}

cv::Scalar severity_colour(core::Severity s) {
  switch (s) {
    case core::Severity::kNone: return kWhite;
    case core::Severity::kWarning: return kYellow;
    case core::Severity::kDanger: return kRed;
  }
  return kWhite;
}

/// Text with its baseline at `origin`, clipped by OpenCV at the image border.
void put_text(cv::Mat& img, const std::string& text, cv::Point origin, double scale,
              const cv::Scalar& colour) {
  cv::putText(img, text, origin, kFont, scale, colour, 1, cv::LINE_AA);
}

void tint_danger(cv::Mat& out, const cv::Mat& danger) {
  if (danger.empty()) return;
  cv::Mat mask = danger;
  if (mask.size() != out.size()) cv::resize(danger, mask, out.size(), 0, 0, cv::INTER_NEAREST);
  cv::Mat tinted;
  cv::addWeighted(out, 1.0 - kTintAlpha, cv::Mat(out.size(), CV_8UC3, kRed), kTintAlpha, 0.0,
                  tinted);
  tinted.copyTo(out, mask);
}

/// Per obstacle: its box and a label of one or two lines, "Z m  TTC t s" and, when the
/// obstacle has a 3D velocity (Stereo-Flow), "v X,Y,Z m/s".
void draw_obstacles(cv::Mat& out, const std::vector<core::Obstacle>& obstacles, double scale,
                    int bar_height) {
  for (const auto& o : obstacles) {
    cv::rectangle(out, o.bbox, kRed, 2);
    std::vector<std::string> lines;
    char text[96];
    if (o.ttc_s) {
      std::snprintf(text, sizeof text, "%.1f m  TTC %.1f s", o.distance_m, *o.ttc_s);
    } else {
      std::snprintf(text, sizeof text, "%.1f m", o.distance_m);
    }
    lines.emplace_back(text);
    if (o.velocity) {
      cv::Vec3d v = *o.velocity;
      for (int i = 0; i < 3; ++i)
        if (std::abs(v[i]) < 0.05) v[i] = 0.0;  // no "-0.0"
      std::snprintf(text, sizeof text, "v %.1f,%.1f,%.1f m/s", v[0], v[1], v[2]);
      lines.emplace_back(text);
    }
    int baseline = 0, width = 0, height = 0;
    for (const auto& line : lines) {
      const cv::Size ts = cv::getTextSize(line, kFont, scale, 1, &baseline);
      width = std::max(width, ts.width);
      height = std::max(height, ts.height);
    }
    const int step = height + baseline + 2;
    const int extra = step * (static_cast<int>(lines.size()) - 1);
    // Above the box when there is room below the bar, else just inside its top edge. y: the
    // first line's baseline.
    int y = o.bbox.y - 3 - extra;
    if (y - height < bar_height) y = o.bbox.y + height + 3;
    const int x = std::max(0, o.bbox.x);
    cv::rectangle(out, cv::Rect(x, y - height - 2, width + 2, step + extra), kBlack, cv::FILLED);
    for (size_t i = 0; i < lines.size(); ++i)
      put_text(out, lines[i], cv::Point(x + 1, y + static_cast<int>(i) * step),
               scale, kRed);
  }
}

/// Top bar: one row of region cells, one row with frame, severity and steering hint.
void draw_bar(cv::Mat& out, const core::Detection& d, double scale, int row_height) {
  const int w = out.cols;
  cv::rectangle(out, cv::Rect(0, 0, w, 2 * row_height), kBlack, cv::FILLED);
  const int n = static_cast<int>(d.regions.size());
  for (int i = 0; i < n; ++i) {
    const int x0 = i * w / n;
    const int x1 = (i + 1) * w / n;
    const auto& r = d.regions[i];
    cv::rectangle(out, cv::Rect(x0, 0, x1 - x0, row_height), r.fired ? kRed : kGreen, cv::FILLED);
    cv::rectangle(out, cv::Rect(x0, 0, x1 - x0, row_height), kBlack, 1);
    cv::Mat cell = out(cv::Rect(x0, 0, x1 - x0, row_height));  // clips long names to the cell
    put_text(cell, r.name, cv::Point(3, row_height - 4), scale, kWhite);
  }
  char status[96];
  std::snprintf(status, sizeof status, "frame %d  %s  %s", d.frame, core::to_string(d.severity),
                steering_text(d.steering));
  put_text(out, status, cv::Point(3, 2 * row_height - 4), scale, severity_colour(d.severity));
}

}  // namespace

cv::Mat draw_overlay(const core::StereoFrame& frame, const core::Detection& detection) {
  cv::Mat out;
  if (frame.left.channels() == 1) {
    cv::cvtColor(frame.left, out, cv::COLOR_GRAY2BGR);
  } else {
    out = frame.left.clone();
  }
  // Text and bar grow with the image so that large frames stay legible.
  const double scale = 0.4 * std::max(1.0, out.cols / 640.0);
  const int row_height = static_cast<int>(16 * std::max(1.0, out.cols / 640.0));
  tint_danger(out, detection.danger);
  draw_obstacles(out, detection.obstacles, scale, 2 * row_height);
  draw_bar(out, detection, scale, row_height);
  return out;
}

OverlayWriter::OverlayWriter(const std::filesystem::path& path, cv::Size size, double fps)
    : path_(path), size_(size) {
  if (size.width <= 0 || size.height <= 0 || !(fps > 0)) {
    throw core::InputError("cannot create overlay video " + path.string() + ": bad size or fps");
  }
  const std::filesystem::path parent = path.parent_path().empty() ? "." : path.parent_path();
  if (!std::filesystem::is_directory(parent)) {
    throw core::InputError("cannot create overlay video (no such folder): " + path.string());
  }
  const int fourcc = cv::VideoWriter::fourcc('m', 'p', '4', 'v');
  // FFmpeg first: it writes mp4 directly; other backends only as a fallback.
  for (int api : {static_cast<int>(cv::CAP_FFMPEG), static_cast<int>(cv::CAP_ANY)}) {
    try {
      writer_.open(path.string(), api, fourcc, fps, size, true);
    } catch (const cv::Exception&) {
      writer_.release();
    }
    if (writer_.isOpened()) break;
  }
  if (!writer_.isOpened()) throw core::InputError("cannot create overlay video: " + path.string());
}

void OverlayWriter::write(const core::StereoFrame& frame, const core::Detection& detection) {
  write(draw_overlay(frame, detection));
}

void OverlayWriter::write(const cv::Mat& overlay) {
  if (!writer_.isOpened()) {
    throw core::InputError("overlay video already closed: " + path_.string());
  }
  cv::Mat image = overlay;
  if (image.size() != size_) cv::resize(image, image, size_, 0, 0, cv::INTER_AREA);
  writer_.write(image);
  ++frames_;
}

void OverlayWriter::close() { writer_.release(); }

}  // namespace sg::io
