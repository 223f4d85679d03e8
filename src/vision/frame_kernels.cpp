#include "sg/vision/frame_kernels.hpp"

#include <string>

#include "sg/core/error.hpp"
#include "sg/vision/coarse_fill.hpp"
#include "sg/vision/flow.hpp"
#include "sg/vision/left_band.hpp"
#include "sg/vision/longseq.hpp"
#include "sg/vision/periodic.hpp"
#include "sg/vision/stereo_bm.hpp"
#include "sg/vision/stereo_fast.hpp"
#include "sg/vision/stereo_sgbm.hpp"

namespace sg::vision {

void check_frame(const core::StereoFrame& frame) {
  if (frame.left.empty() || frame.left.type() != CV_8UC1 || frame.right.type() != CV_8UC1 ||
      frame.left.size() != frame.right.size()) {
    throw core::InputError("frame " + std::to_string(frame.index) +
                           ": left and right must be 8-bit gray images of the same size");
  }
}

namespace {

/// The row matcher of a matcher setting; nullptr for longseq, which has its own parameters.
RowMatcher row_matcher(core::Matcher matcher) {
  switch (matcher) {
    case core::Matcher::kBm:
      return match_bm_rows;
    case core::Matcher::kSgbm:
      return match_sgbm_rows;
    case core::Matcher::kFast:
      return match_fast_rows;
    case core::Matcher::kLongSeq:
      return nullptr;
  }
  return nullptr;
}

}  // namespace

void disparity_rows(const core::StereoFrame& frame, const core::DetectorParams& params,
                    cv::Mat& disp, cv::Range rows) {
  const RowMatcher match = row_matcher(params.bm.matcher);
  if (!match) {  // longseq
    LongSeqParams p;
    p.num_disparities = params.bm.num_disparities;
    p.window_px = params.bm.block_size;
    p.cost_max = params.bm.longseq_cost_max;
    p.best_max = params.bm.longseq_best_max;
    p.both_ways = params.bm.longseq_both_ways;
    longseq_disparity_rows(frame.left, frame.right, p, disp, rows);
    return;
  }
  match(frame.left, frame.right, params.bm, disp, rows);
  if (params.bm.left_band) match_left_band_rows(match, frame.left, frame.right, params.bm, disp, rows);
}

void disparity_finish(const core::StereoFrame& frame, const core::DetectorParams& params,
                      cv::Mat& disp) {
  filter_speckles(disp, params.bm);
  // The block matchers' holes only: sgbm's maps are dense, longseq is a different method.
  const bool block_matcher =
      params.bm.matcher == core::Matcher::kBm || params.bm.matcher == core::Matcher::kFast;
  // Repeats fool every whole-pixel matcher; longseq stays the method the thesis describes.
  cv::Mat periodic;
  if (params.bm.periodic_ratio > 0 && params.bm.matcher != core::Matcher::kLongSeq) {
    periodic = periodic_mask(frame.left, params.bm);
    disp.setTo(-1.0f, periodic);
  }
  if (params.bm.coarse_fill && block_matcher) {
    fill_from_half_size(frame.left, frame.right, params.bm, row_matcher(params.bm.matcher), disp);
    if (!periodic.empty()) disp.setTo(-1.0f, periodic);  // the half-size pair repeats as well
  }
}

void flow_rows(const cv::Mat& current, const cv::Mat& previous,
               const core::DetectorParams& params, cv::Mat& flow, cv::Range rows) {
  compute_flow_rows(current, previous, params.flow, flow, rows);
}

void allocate_maps(cv::Size size, bool with_flow, cv::Mat& disp, cv::Mat& flow) {
  disp.create(size, CV_32F);
  if (with_flow) flow.create(size, CV_32FC2);
}

}  // namespace sg::vision
