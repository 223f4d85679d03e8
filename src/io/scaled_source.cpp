#include "sg/io/scaled_source.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "sg/core/error.hpp"

namespace sg::io {
namespace {

/// Resizes both images of `frame` from `from` to `size`. A frame of another size is not resized
/// into shape (that would hide a broken input): left and right of different sizes pass on for the
/// pipeline's frame check to report, and a pair of an unexpected size is an InputError here.
core::StereoFrame resize_frame(core::StereoFrame frame, cv::Size from, cv::Size size) {
  if (frame.left.size() != frame.right.size()) return frame;
  if (frame.left.size() != from) {
    throw core::InputError("frame " + std::to_string(frame.index) + " is " +
                           std::to_string(frame.left.cols) + "x" + std::to_string(frame.left.rows) +
                           ", the stream is " + std::to_string(from.width) + "x" +
                           std::to_string(from.height));
  }
  auto resize = [size](const cv::Mat& in) {
    cv::Mat out;
    const bool shrink = size.width < in.cols || size.height < in.rows;
    cv::resize(in, out, size, 0, 0, shrink ? cv::INTER_AREA : cv::INTER_LINEAR);
    return out;
  };
  frame.left = resize(frame.left);
  frame.right = resize(frame.right);
  return frame;
}

}  // namespace

std::vector<std::string> validate_scale(double scale, cv::Size size) {
  std::vector<std::string> out;
  std::ostringstream value;
  value << scale;
  if (!std::isfinite(scale) || scale <= 0 || scale > kMaxScale) {
    out.push_back("scale=" + value.str() + ": must be a finite number in (0, 4]");
    return out;
  }
  const cv::Size to = scaled_size(size, scale);
  if (to.width < kMinScaledWidth || to.height < kMinScaledHeight) {
    out.push_back("scale=" + value.str() + ": gives " + std::to_string(to.width) + "x" +
                  std::to_string(to.height) + " images from " + std::to_string(size.width) + "x" +
                  std::to_string(size.height) + ", smaller than the minimum " +
                  std::to_string(kMinScaledWidth) + "x" + std::to_string(kMinScaledHeight));
  }
  return out;
}

cv::Size scaled_size(cv::Size size, double scale) {
  return {static_cast<int>(std::lround(size.width * scale)),
          static_cast<int>(std::lround(size.height * scale))};
}

core::Camera scale_camera(const core::Camera& camera, cv::Size to) {
  const double sx = static_cast<double>(to.width) / camera.width;
  const double sy = static_cast<double>(to.height) / camera.height;
  core::Camera out = camera;
  out.width = to.width;
  out.height = to.height;
  out.focal_px = camera.focal_px * sx;
  out.cx = (camera.cx + 0.5) * sx - 0.5;
  out.cy = (camera.cy + 0.5) * sy - 0.5;
  return out;
}

ScaledSource::ScaledSource(std::unique_ptr<core::FrameSource> inner, double scale)
    : inner_(std::move(inner)) {
  const core::Camera& cam = inner_->camera();
  core::throw_if_invalid(validate_scale(scale, {cam.width, cam.height}), "--scale");
  from_ = {cam.width, cam.height};
  size_ = scaled_size(from_, scale);
  camera_ = scale_camera(cam, size_);
}

std::optional<core::StereoFrame> ScaledSource::next() {
  std::optional<core::StereoFrame> frame = inner_->next();
  if (!frame) return std::nullopt;
  return resize_frame(std::move(*frame), from_, size_);
}

std::optional<core::PendingFrame> ScaledSource::next_pending() {
  std::optional<core::PendingFrame> pending = inner_->next_pending();
  if (!pending) return std::nullopt;
  pending->load = [load = std::move(pending->load), from = from_, size = size_] {
    return resize_frame(load(), from, size);
  };
  return pending;
}

std::unique_ptr<core::FrameSource> scale_source(std::unique_ptr<core::FrameSource> source,
                                                double scale) {
  if (scale == 1.0) return source;
  return std::make_unique<ScaledSource>(std::move(source), scale);
}

}  // namespace sg::io
