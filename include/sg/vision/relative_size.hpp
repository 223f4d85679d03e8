#pragma once
/// Relative size cues (thesis 3.1.2, DESIGN 3.4, after the thesis' [24]): a monocular cue. A
/// feature of an approaching object grows from one frame to the next. Features are matched
/// between frames (ORB: SURF is not in Debian's OpenCV), those whose detected size grew get a
/// finer scale from templates: the patch around the feature in the earlier frame against patches
/// s times larger in the later one, both resampled to one grid, for the s of least error. (The
/// thesis divides a sum of squared differences by s^2, the area ratio; the mean over one
/// resampled grid is the same normalisation.) A cluster of nearby features expanding by at least
/// s_min is an approaching obstacle.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sg/core/surveyed_params.hpp"

namespace sg::vision {

using RelativeSizeParams = core::RelativeSizeParams;

using core::validate;

/// The scale s (later size / earlier size) of the patch of side `side_px` centred at `at_prev`
/// in `prev` seen at `at_cur` in `cur` (8-bit grey): the least mean absolute error between the
/// resampled templates over the search range, refined by a parabola. `error` receives that
/// error; returns 0 when a template leaves an image. The scales lie on a logarithmic grid of
/// scale_step; with coarse_stride > 1 every coarse_stride-th is tried first, then every one within
/// a stride of the best (expanding_features uses 4: 17 templates a feature instead of 44 for its
/// growing scales).
double patch_scale(const cv::Mat& prev, const cv::Mat& cur, cv::Point2f at_prev,
                   cv::Point2f at_cur, double side_px, const RelativeSizeParams& p,
                   double* error = nullptr, int coarse_stride = 1);

struct ExpandingFeature {
  cv::Point2f at;  ///< in the later frame, px
  double scale = 1.0;
  int cluster = -1;  ///< index of its cluster, -1 when in none big enough
};

/// Features matched from `prev` to `cur` (8-bit grey, one size) whose template scale reaches
/// s_min, clustered (single linkage within cluster_radius_px; clusters smaller than cluster_min
/// get -1). Throws core::InputError on bad images or parameters.
std::vector<ExpandingFeature> expanding_features(const cv::Mat& prev, const cv::Mat& cur,
                                                 const RelativeSizeParams& p);

}  // namespace sg::vision
