#pragma once
/// Rectified stereo camera model. Conventions (DESIGN.md): camera frame x right, y down, z forward,
/// metres; a left pixel (x, y) matches right pixel (x - d, y), disparity d >= 0.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace sg::core {

struct Camera {
  int width = 640;           ///< image width, px
  int height = 480;          ///< image height, px
  double focal_px = 500.0;   ///< focal length, px (same for x and y)
  double baseline_m = 0.12;  ///< distance between the optical centres, m
  double cx = 319.5;         ///< principal point x, px
  double cy = 239.5;         ///< principal point y, px
  double fps = 30.0;         ///< frame rate, Hz

  /// Depth Z = f*B/d in metres for a disparity d > 0 px.
  double depth(double disparity_px) const { return focal_px * baseline_m / disparity_px; }
  /// Disparity d = f*B/Z in px for a depth Z > 0 m.
  double disparity(double depth_m) const { return focal_px * baseline_m / depth_m; }
  /// 3D point (X, Y, Z) in metres of pixel (x, y) with disparity d > 0.
  cv::Point3d point(double x, double y, double disparity_px) const {
    const double z = depth(disparity_px);
    return {(x - cx) * z / focal_px, (y - cy) * z / focal_px, z};
  }
  /// Pixel (x, y) of a 3D point with Z > 0.
  cv::Point2d project(const cv::Point3d& p) const {
    return {cx + focal_px * p.x / p.z, cy + focal_px * p.y / p.z};
  }
  /// Seconds between frames.
  double frame_period() const { return 1.0 / fps; }
};

/// Physical upper bounds checked by validate(Camera): beyond them a value is a typo or a broken
/// calibration, not a camera.
inline constexpr double kMaxFps = 10000.0;       ///< Hz (high-speed cameras reach a few thousand)
inline constexpr double kMaxFocalPx = 1.0e5;     ///< px
inline constexpr double kMaxBaselineM = 100.0;   ///< m

/// Every violation as "camera.<field>=<value>: <rule>"; empty when valid: sizes positive; focal,
/// baseline and fps finite, positive and below the kMax bounds; cx, cy finite.
std::vector<std::string> validate(const Camera& camera);

}  // namespace sg::core
