#pragma once
/// Dense optical flow (DESIGN 2.2): OpenCV DISOpticalFlow presets or Farneback, computed BACKWARD,
/// from the current left image to the previous one.
#include <opencv2/core.hpp>
#include <opencv2/video/tracking.hpp>
#include <string>
#include <vector>

namespace sg::vision {

enum class FlowMethod { kDisUltrafast, kDisFast, kDisMedium, kFarneback };

/// "dis-ultrafast" / "dis-fast" / "dis-medium" / "farneback".
const char* to_string(FlowMethod m);
/// Parses the names of to_string(); throws core::InputError naming the text otherwise.
FlowMethod parse_flow_method(const std::string& text);

struct FlowParams {
  FlowMethod method = FlowMethod::kDisUltrafast;
  /// Rows of context a tile reads above and below its own rows (compute_flow_rows), px. DIS and
  /// Farneback work on pyramids, so a tile differs from the whole image near its cut anyway.
  int tile_halo_px = 48;
  // Farneback only (cv::calcOpticalFlowFarneback); OpenCV's sample values.
  double fb_pyr_scale = 0.5;  ///< pyramid scale between levels, in (0, 1)
  int fb_levels = 3;          ///< pyramid levels, >= 1
  int fb_win_size = 15;       ///< averaging window, px, >= 3
  int fb_iterations = 3;      ///< iterations per level, >= 1
  int fb_poly_n = 5;          ///< polynomial expansion neighbourhood, 5 or 7
  double fb_poly_sigma = 1.2;  ///< Gaussian sigma of the expansion, > 0 (1.1 for n=5, 1.5 for 7)
};

/// Every violation as "flow.<field>=<value>: <rule>"; empty when valid.
std::vector<std::string> validate(const FlowParams& p);

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
