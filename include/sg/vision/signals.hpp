#pragma once
/// From dangerous pixels to signals (DESIGN 3.3): clean-up, obstacles, regions, hysteresis,
/// severity, steering hint.
#include <deque>
#include <opencv2/core.hpp>
#include <vector>

#include "sg/core/camera.hpp"
#include "sg/core/detection.hpp"
#include "sg/core/params.hpp"

namespace sg::vision {

/// Pixels [x0, x1) of row y belong to obstacle `obstacle` (an index into extract_obstacles' result).
struct ObstacleRun {
  int y = 0, x0 = 0, x1 = 0;
  int obstacle = 0;
};

/// Opening with an open_size square, then connected components (8-connected); blobs smaller than
/// min_area_px are removed from `mask` (in place). Returns one Obstacle per kept blob, in
/// raster order of their first pixel: bbox, pixels, median depth (m) of the blob's pixels with
/// disparity > 0 (0 when none), median TTC (s) of finite ttc values (empty when none); medians of
/// an even count average the two middle values. mask: CV_8U 0/255; disp: CV_32F (invalid < 0);
/// ttc: CV_32F (NaN = none); all the same size. When `velocity` (CV_32FC3, m/s, NaN = unknown,
/// the size of the mask) is given, each obstacle's velocity is the mean over its pixels whose
/// three components are finite (left empty when none). When `runs` is given, it receives the
/// kept blobs' pixels as row runs, each naming its obstacle's index in the result.
std::vector<core::Obstacle> extract_obstacles(cv::Mat& mask, const cv::Mat& disp,
                                              const cv::Mat& ttc, const core::Camera& camera,
                                              const core::SignalParams& p,
                                              const cv::Mat& velocity = cv::Mat(),
                                              std::vector<ObstacleRun>* runs = nullptr);

/// Clears from `mask` the blobs of the obstacles not `keep`: runs as extract_obstacles gave them,
/// keep[i] for obstacle i. Returns whether any pixel was cleared.
bool clear_obstacles(cv::Mat& mask, const std::vector<ObstacleRun>& runs,
                     const std::vector<bool>& keep);

/// Names of `columns` regions: {"left", "centre", "right"} for 3, else "r0", "r1", ...
std::vector<std::string> region_names(int columns);

/// Dangerous (non-zero) pixels in each of `columns` columns of the mask; column c covers
/// x in [c*W/columns, (c+1)*W/columns).
std::vector<int> count_region_pixels(const cv::Mat& mask, int columns);

/// Per-region hysteresis: a region turns on after on_k of the last on_n frames were dangerous
/// (count > region_min_px) and off after off_m consecutive clear frames (its history is then
/// forgotten). The number of regions is taken from the first update.
class RegionHysteresis {
 public:
  explicit RegionHysteresis(const core::SignalParams& p);
  std::vector<core::RegionSignal> update(const std::vector<int>& region_pixels);

 private:
  core::SignalParams p_;
  std::vector<std::deque<bool>> history_;
  std::vector<int> clear_run_;
  std::vector<bool> on_;
};

/// none / warning / danger by the smallest obstacle TTC (danger when <= ttc_danger_s, warning when
/// <= ttc_warning_s, else none); none when `signal` is false; warning when `signal` is true but no
/// obstacle has a TTC (a signal held on by hysteresis).
core::Severity severity_of(bool signal, const std::vector<core::Obstacle>& obstacles,
                           const core::SignalParams& p);

/// Straight when no region fired or the centre is clear; otherwise the clear side with the fewest
/// dangerous pixels (left on ties); stop when every region fired. Other column counts: the
/// centre-most clear column (ties: fewer dangerous pixels, then left) gives the side; straight if
/// it is the middle one of an odd count.
core::Steering steering_hint(const std::vector<core::RegionSignal>& regions);

}  // namespace sg::vision
