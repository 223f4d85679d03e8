#pragma once
/// Stereo accuracy evaluation (`stereoguard eval --stereo`): each matcher on each pair of a GT
/// dataset, scored by eval::score_disparity, with its time per frame.
#include <functional>
#include <string>
#include <vector>

#include "sg/core/params.hpp"
#include "sg/eval/stereo_metrics.hpp"
#include "sg/io/stereo_gt.hpp"

namespace sg::pipeline {

/// A matcher to evaluate, under the label shown in the table (e.g. "fast-census").
struct StereoMatcherEntry {
  std::string label;
  core::BmParams params;
};

/// Parses "bm", "sgbm", "fast", "fast-sad", "fast-census", "longseq" (each the matcher alone,
/// without the half-size fill or the periodic check), "fast-filled" (fast with its holes filled
/// from the half-size pair) or "fast-periodic" (fast with the matches on repeating texture
/// dropped, vision/periodic.hpp) into an entry built on `base` (range, block size,
/// thresholds); throws core::InputError otherwise.
StereoMatcherEntry parse_matcher_entry(const std::string& text, const core::BmParams& base);

struct StereoEvalRow {
  std::string pair, matcher;
  int num_disparities = 0, block_size = 0;
  eval::StereoScores scores;
  double ms = 0;  ///< matching time (raw match + speckle filter), best of 3 runs, ms
};

/// Runs every matcher on every pair (images read as gray). When `auto_range`, each pair's
/// num_disparities is its largest GT disparity + 1 rounded up to 16 (the same for every matcher);
/// else the entries' own. Calls `on_row` after each (pair, matcher). Throws core::InputError on
/// unreadable files or sizes that differ.
std::vector<StereoEvalRow> evaluate_stereo(const std::vector<io::StereoGtPair>& pairs,
                                           const std::vector<StereoMatcherEntry>& matchers,
                                           bool auto_range,
                                           const std::function<void(const StereoEvalRow&)>& on_row);

}  // namespace sg::pipeline
