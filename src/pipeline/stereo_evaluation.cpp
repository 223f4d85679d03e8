#include "sg/pipeline/stereo_evaluation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/imgcodecs.hpp>

#include "sg/core/error.hpp"
#include "sg/io/stereo_gt.hpp"
#include "sg/vision/frame_kernels.hpp"

namespace sg::pipeline {

StereoMatcherEntry parse_matcher_entry(const std::string& text, const core::BmParams& base) {
  StereoMatcherEntry e{text, base};
  // The matcher alone, unless the label asks for the filled map or the repeats dropped.
  e.params.coarse_fill = false;
  e.params.periodic_ratio = 0.0;
  if (text == "fast-periodic") {
    e.params.matcher = core::Matcher::kFast;
    e.params.periodic_ratio =
        base.periodic_ratio > 0 ? base.periodic_ratio : core::BmParams{}.periodic_ratio;
    return e;
  }
  if (text == "fast-filled") {
    e.params.matcher = core::Matcher::kFast;
    e.params.coarse_fill = true;
    return e;
  }
  if (text == "fast-sad" || text == "fast-census") {
    e.params.matcher = core::Matcher::kFast;
    e.params.cost = text == "fast-sad" ? core::MatchCost::kSad : core::MatchCost::kCensus;
    return e;
  }
  try {
    e.params.matcher = core::parse_matcher(text);
  } catch (const core::InputError&) {
    throw core::InputError("matchers=" + text +
                           ": each must be bm, sgbm, fast, fast-sad, "
                           "fast-census, fast-filled, fast-periodic or longseq");
  }
  return e;
}

std::vector<StereoEvalRow> evaluate_stereo(
    const std::vector<io::StereoGtPair>& pairs, const std::vector<StereoMatcherEntry>& matchers,
    bool auto_range, const std::function<void(const StereoEvalRow&)>& on_row) {
  std::vector<StereoEvalRow> rows;
  for (const io::StereoGtPair& pair : pairs) {
    core::StereoFrame frame;
    frame.left = cv::imread(pair.left.string(), cv::IMREAD_GRAYSCALE);
    frame.right = cv::imread(pair.right.string(), cv::IMREAD_GRAYSCALE);
    if (frame.left.empty()) throw core::InputError("cannot read image " + pair.left.string());
    if (frame.right.empty()) throw core::InputError("cannot read image " + pair.right.string());
    const cv::Mat gt = io::read_stereo_gt(pair.gt, pair.scale);
    if (frame.left.size() != frame.right.size() || gt.size() != frame.left.size()) {
      throw core::InputError(pair.name + ": left, right and GT sizes differ");
    }
    double gt_max = 0;
    cv::minMaxLoc(gt, nullptr, &gt_max);
    for (const StereoMatcherEntry& m : matchers) {
      core::DetectorParams params;
      params.bm = m.params;
      if (auto_range)
        params.bm.num_disparities = std::max(16, (static_cast<int>(gt_max) + 16) / 16 * 16);
      std::vector<std::string> problems = core::validate(params.bm);
      if (params.bm.min_disparity + params.bm.num_disparities >= frame.left.cols)
        problems.push_back(pair.name + ": num_disparities must be below the image width");
      core::throw_if_invalid(problems, "invalid stereo settings for " + m.label);
      // The best of three runs: the figure least disturbed by other processes.
      cv::Mat disp(frame.left.size(), CV_32F);
      double best_ms = 0;
      for (int run = 0; run < 3; ++run) {
        const auto t0 = std::chrono::steady_clock::now();
        vision::disparity_rows(frame, params, disp, cv::Range::all());
        vision::disparity_finish(frame, params, disp);
        const auto t1 = std::chrono::steady_clock::now();
        const double ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
        best_ms = run == 0 ? ms : std::min(best_ms, ms);
      }
      StereoEvalRow row;
      row.pair = pair.name;
      row.matcher = m.label;
      row.num_disparities = params.bm.num_disparities;
      row.block_size = params.bm.block_size;
      row.scores = eval::score_disparity(disp, gt);
      row.ms = best_ms;
      if (on_row) on_row(row);
      rows.push_back(row);
    }
  }
  return rows;
}

}  // namespace sg::pipeline
