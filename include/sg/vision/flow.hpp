#pragma once
/// Dense optical flow (DESIGN 2.2): OpenCV DISOpticalFlow presets or Farneback, computed BACKWARD,
/// from the current left image to the previous one.
#include <opencv2/core.hpp>
#include <opencv2/video/tracking.hpp>
#include <string>
#include <vector>

#include "sg/core/params.hpp"

namespace sg::vision {

// The flow settings live in core (DetectorParams.flow); these names keep vision code short.
using core::FlowMethod;
using core::FlowParams;
using core::parse_flow_method;
using core::to_string;
using core::validate;

/// Backward flow B from `current` to `previous`: the point at pixel p of `current` was at
/// q = p + B(p) in `previous` (so previous(q) ~ current(p)). Both images CV_8UC1, same size, at
/// least 16x16 (InputError otherwise). flow: CV_32FC2 (u, v) in px, allocated by the call.
/// The result does not depend on OpenCV's thread count. p must be valid.
void compute_flow(const cv::Mat& current, const cv::Mat& previous, const FlowParams& p,
                  cv::Mat& flow);

/// Rows a tile of output rows [r0, r1) reads: [r0 - tile_halo_px, r1 + tile_halo_px) clipped.
cv::Range flow_input_rows(cv::Range rows, const FlowParams& p, int height);

/// Flow of output rows `rows` only: compute_flow on the input rows of flow_input_rows, copied
/// into rows `rows` of `flow` (CV_32FC2 of the full size, allocated if needed; other rows are left
/// untouched). Near a cut the result differs slightly from the whole-image flow (pyramids).
void compute_flow_rows(const cv::Mat& current, const cv::Mat& previous, const FlowParams& p,
                       cv::Mat& flow, cv::Range rows);

/// Owns the OpenCV flow object so that consecutive frames reuse its buffers; compute() gives the
/// same result as compute_flow. One instance per thread (OpenCV's objects are not re-entrant).
class FlowEstimator {
 public:
  /// p must be valid.
  explicit FlowEstimator(const FlowParams& p);
  void compute(const cv::Mat& current, const cv::Mat& previous, cv::Mat& flow);
  const FlowParams& params() const { return params_; }

 private:
  FlowParams params_;
  cv::Ptr<cv::DISOpticalFlow> dis_;  ///< null for Farneback
};

}  // namespace sg::vision
