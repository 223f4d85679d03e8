#include "sg/vision/flow.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "sg/core/error.hpp"

namespace sg::vision {
namespace {

constexpr int kMinSide = 16;  // below this DIS has no pyramid level to work on

void check_inputs(const cv::Mat& current, const cv::Mat& previous) {
  if (current.empty() || previous.empty())
    throw core::InputError("flow: an input image is empty");
  if (current.type() != CV_8UC1 || previous.type() != CV_8UC1)
    throw core::InputError("flow: images must be 8-bit single-channel (CV_8UC1)");
  if (current.size() != previous.size()) {
    std::ostringstream s;
    s << "flow: image sizes differ (" << current.cols << "x" << current.rows << " vs "
      << previous.cols << "x" << previous.rows << ")";
    throw core::InputError(s.str());
  }
  if (current.cols < kMinSide || current.rows < kMinSide)
    throw core::InputError("flow: images must be at least 16x16 px");
}

int dis_preset(FlowMethod m) {
  switch (m) {
    case FlowMethod::kDisFast:
      return cv::DISOpticalFlow::PRESET_FAST;
    case FlowMethod::kDisMedium:
      return cv::DISOpticalFlow::PRESET_MEDIUM;
    default:
      return cv::DISOpticalFlow::PRESET_ULTRAFAST;
  }
}

// calcOpticalFlowFarneback(prev, next) finds prev(p) ~ next(p + flow(p)): with prev = current and
// next = previous that is our backward flow.
void farneback(const cv::Mat& current, const cv::Mat& previous, const FlowParams& p,
               cv::Mat& flow) {
  cv::calcOpticalFlowFarneback(current, previous, flow, p.fb_pyr_scale, p.fb_levels,
                               p.fb_win_size, p.fb_iterations, p.fb_poly_n, p.fb_poly_sigma, 0);
}

}  // namespace

FlowEstimator::FlowEstimator(const FlowParams& p) : params_(p) {
  if (p.method != FlowMethod::kFarneback) dis_ = cv::DISOpticalFlow::create(dis_preset(p.method));
}

void FlowEstimator::compute(const cv::Mat& current, const cv::Mat& previous, cv::Mat& flow) {
  check_inputs(current, previous);
  if (dis_) {
    // DIS estimates I0(p) ~ I1(p + flow(p)): I0 = current, I1 = previous is backward flow.
    // Its parallel loops use a fixed stripe count, so the result is thread-count independent.
    dis_->calc(current, previous, flow);
  } else {
    farneback(current, previous, params_, flow);
  }
}

void compute_flow(const cv::Mat& current, const cv::Mat& previous, const FlowParams& p,
                  cv::Mat& flow) {
  FlowEstimator(p).compute(current, previous, flow);
}

cv::Range flow_input_rows(cv::Range rows, const FlowParams& p, int height) {
  if (rows == cv::Range::all()) return {0, height};
  return {std::max(0, rows.start - p.tile_halo_px), std::min(height, rows.end + p.tile_halo_px)};
}

void compute_flow_rows(const cv::Mat& current, const cv::Mat& previous, const FlowParams& p,
                       cv::Mat& flow, cv::Range rows) {
  check_inputs(current, previous);
  if (rows == cv::Range::all()) rows = cv::Range(0, current.rows);
  if (rows.start < 0 || rows.end > current.rows || rows.start >= rows.end)
    throw core::InputError("flow: row range outside the image");
  flow.create(current.size(), CV_32FC2);
  const cv::Range in = flow_input_rows(rows, p, current.rows);
  cv::Mat tile;
  compute_flow(current.rowRange(in), previous.rowRange(in), p, tile);
  tile.rowRange(rows.start - in.start, rows.end - in.start).copyTo(flow.rowRange(rows));
}

}  // namespace sg::vision
