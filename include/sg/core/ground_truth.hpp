#pragma once
/// Ground truth for one frame, as the simulator produces it and the stereo folder's gt/ stores it.
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

namespace sg::core {

struct ObstacleTruth {
  int id = 0;                    ///< object id (>= 1), as in the ids map
  bool colliding = false;        ///< its path enters the safety envelope within the horizon
  std::optional<double> ttc_s;   ///< time until it enters the envelope, s; empty if it never does
  int pixels = 0;                ///< visible pixels in the left image
};

struct FrameTruth {
  int frame = 0;
  bool alarm = false;  ///< a colliding obstacle covers at least min_area pixels
  std::vector<ObstacleTruth> obstacles;
};

/// Dense ground truth of the left image; any map may be empty when unknown.
struct TruthMaps {
  cv::Mat disparity;  ///< CV_32F, px; 0 = unknown
  cv::Mat flow;       ///< CV_32FC2 backward flow (frame i -> i-1): p + flow(p) = position in i-1
  cv::Mat danger;     ///< CV_8U, 255 = pixel of a colliding obstacle
  cv::Mat ids;        ///< CV_16U object id, 0 = background (ground, far wall)
};

}  // namespace sg::core
