#pragma once
/// `--scale S`: a FrameSource decorator that resizes every frame of another source (DESIGN 1, the
/// emitter's "optionally resizes"). The resize runs in PendingFrame::load, after the inner load,
/// so that it leaves the serial emitter along with the decode.
#include <memory>
#include <string>
#include <vector>

#include "sg/core/source.hpp"

namespace sg::io {

/// Smallest scaled image accepted, px: below this no matcher finds anything useful.
inline constexpr int kMinScaledWidth = 64;
inline constexpr int kMinScaledHeight = 48;
/// Largest scale factor accepted.
inline constexpr double kMaxScale = 4.0;

/// Every violation of scale factor `scale` for a `size` image as text, e.g.
/// "scale=0: must be a finite number in (0, 4]"; empty when valid.
std::vector<std::string> validate_scale(double scale, cv::Size size);

/// Size of a `size` image scaled by `scale`: each side rounded to the nearest pixel.
cv::Size scaled_size(cv::Size size, double scale);

/// The camera of images resized from camera.width x camera.height to `to`. cv::resize maps the
/// centre of destination pixel x_d to source x_s = (x_d + 0.5) / s - 0.5 with s = to.width /
/// width, so a principal point cx becomes (cx + 0.5) * s - 0.5 (likewise cy with the vertical
/// factor). focal_px scales by the horizontal factor (disparity is horizontal); baseline and fps
/// are unchanged.
core::Camera scale_camera(const core::Camera& camera, cv::Size to);

/// Resizes each frame of `inner` by `scale` (INTER_AREA when shrinking, INTER_LINEAR when
/// enlarging) and reports the scaled camera. next() and next_pending() + load() give the same
/// frames. Throws core::InputError from the constructor for an invalid scale.
class ScaledSource : public core::FrameSource {
 public:
  ScaledSource(std::unique_ptr<core::FrameSource> inner, double scale);
  std::optional<core::StereoFrame> next() override;
  std::optional<core::PendingFrame> next_pending() override;
  const core::Camera& camera() const override { return camera_; }
  int size() const override { return inner_->size(); }
  bool live() const override { return inner_->live(); }
  /// The source being scaled.
  core::FrameSource& inner() { return *inner_; }

 private:
  std::unique_ptr<core::FrameSource> inner_;
  cv::Size from_, size_;  ///< image size before and after scaling, px
  core::Camera camera_;
};

/// `source` unchanged when `scale` is 1, else wrapped in a ScaledSource.
std::unique_ptr<core::FrameSource> scale_source(std::unique_ptr<core::FrameSource> source,
                                                double scale);

}  // namespace sg::io
