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

const char* to_string(FlowMethod m) {
  switch (m) {
    case FlowMethod::kDisUltrafast:
      return "dis-ultrafast";
    case FlowMethod::kDisFast:
      return "dis-fast";
    case FlowMethod::kDisMedium:
      return "dis-medium";
    case FlowMethod::kFarneback:
      return "farneback";
  }
  return "?";
}

FlowMethod parse_flow_method(const std::string& text) {
  for (FlowMethod m : {FlowMethod::kDisUltrafast, FlowMethod::kDisFast, FlowMethod::kDisMedium,
                       FlowMethod::kFarneback})
    if (text == to_string(m)) return m;
  throw core::InputError("flow.method=" + text +
                         ": must be dis-ultrafast, dis-fast, dis-medium or farneback");
}

std::vector<std::string> validate(const FlowParams& p) {
  std::vector<std::string> out;
  auto require = [&out](bool ok, const char* field, auto value, const char* rule) {
    if (ok) return;
    std::ostringstream s;
    s << "flow." << field << "=" << value << ": " << rule;
    out.push_back(s.str());
  };
  require(p.tile_halo_px >= 0, "tile_halo_px", p.tile_halo_px, "must be >= 0");
  if (p.method != FlowMethod::kFarneback) return out;
  require(std::isfinite(p.fb_pyr_scale) && p.fb_pyr_scale > 0 && p.fb_pyr_scale < 1,
          "fb_pyr_scale", p.fb_pyr_scale, "must be in (0, 1)");
  require(p.fb_levels >= 1, "fb_levels", p.fb_levels, "must be >= 1");
  require(p.fb_win_size >= 3, "fb_win_size", p.fb_win_size, "must be >= 3");
  require(p.fb_iterations >= 1, "fb_iterations", p.fb_iterations, "must be >= 1");
  require(p.fb_poly_n == 5 || p.fb_poly_n == 7, "fb_poly_n", p.fb_poly_n, "must be 5 or 7");
  require(std::isfinite(p.fb_poly_sigma) && p.fb_poly_sigma > 0, "fb_poly_sigma", p.fb_poly_sigma,
          "must be > 0");
  return out;
}

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
