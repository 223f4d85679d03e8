#pragma once
#include <opencv2/core.hpp>

namespace sg::core {

/// One rectified stereo pair as it leaves a source: 8-bit gray, equal sizes.
struct StereoFrame {
  int index = 0;        ///< 0-based frame number in the stream
  double time_s = 0.0;  ///< stream time of acquisition, s (index / fps for recorded input)
  cv::Mat left;         ///< CV_8UC1
  cv::Mat right;        ///< CV_8UC1, same size as left
};

}  // namespace sg::core
