#pragma once
/// Synthetic inputs for the vision tests: textured stereo pairs with known disparity.
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "sg/core/camera.hpp"

namespace sg::vision::test {

/// A small camera for hand-made maps: f*B = 50 px*m, 10 fps, 161 x 121.
inline core::Camera camera() {
  core::Camera c;
  c.width = 161;
  c.height = 121;
  c.focal_px = 100.0;
  c.baseline_m = 0.5;
  c.cx = 80.0;
  c.cy = 60.0;
  c.fps = 10.0;
  return c;
}

/// Smooth random texture (blurred uniform noise, full 0..255 range), fixed seed.
inline cv::Mat texture(cv::Size size, uint64_t seed, double sigma = 1.0) {
  cv::RNG rng(seed);
  cv::Mat noise(size, CV_8U);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::Mat smooth;
  cv::GaussianBlur(noise, smooth, cv::Size(0, 0), sigma);
  cv::normalize(smooth, smooth, 0, 255, cv::NORM_MINMAX);
  return smooth;
}

/// Frames of a textured square in front of a static textured background, 480 x 360: the square,
/// `side` px wide, centred at (240, 180) (the relative-size tests grow it between frames).
inline cv::Mat square_before_background(double side) {
  static const cv::Mat background = texture({480, 360}, 5, 1.5);
  static const cv::Mat object = texture({400, 400}, 9, 1.5);
  cv::Mat f = background.clone();
  cv::Mat patch;
  cv::resize(object, patch, cv::Size(cvRound(side), cvRound(side)), 0, 0, cv::INTER_AREA);
  patch.copyTo(f(cv::Rect(240 - patch.cols / 2, 180 - patch.rows / 2, patch.cols, patch.rows)));
  return f;
}

/// A rectified pair where every left pixel (x, y) matches right pixel (x - d, y): the right image
/// is the left texture sampled at x + d (bilinear for fractional d).
struct StereoPair {
  cv::Mat left, right;
};

inline StereoPair shifted_pair(cv::Size size, float d, uint64_t seed) {
  const int margin = static_cast<int>(d) + 4;
  cv::Mat wide = texture({size.width + margin, size.height}, seed, 1.2);
  cv::Mat map_x(size, CV_32F), map_y(size, CV_32F);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      map_x.at<float>(y, x) = static_cast<float>(x) + d;
      map_y.at<float>(y, x) = static_cast<float>(y);
    }
  StereoPair p;
  p.left = wide(cv::Rect(0, 0, size.width, size.height)).clone();
  cv::remap(wide, p.right, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return p;
}

/// A scene with structure: background at disparity 6, a nearer box at 21, a slanted strip, and a
/// flat (textureless) patch, so that BM output mixes valid, invalid and occluded pixels.
inline StereoPair scene_pair(cv::Size size, uint64_t seed) {
  cv::Mat tex = texture({size.width + 64, size.height}, seed, 1.0);
  cv::Mat flat = tex.clone();
  flat(cv::Rect(size.width / 2, size.height / 5, size.width / 6, size.height / 4)).setTo(128);
  cv::Mat map_x(size, CV_32F), map_y(size, CV_32F);
  const cv::Rect box(size.width / 5, size.height / 3, size.width / 4, size.height / 3);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      float d = 6.0f;
      if (box.contains({x, y})) d = 21.0f;
      if (x > 3 * size.width / 4) d = 6.0f + 10.0f * static_cast<float>(y) / size.height;
      // Right pixel x shows the left texture at x + d.
      map_x.at<float>(y, x) = static_cast<float>(x) + d;
      map_y.at<float>(y, x) = static_cast<float>(y);
    }
  StereoPair p;
  p.left = flat(cv::Rect(0, 0, size.width, size.height)).clone();
  cv::remap(flat, p.right, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return p;
}

}  // namespace sg::vision::test
