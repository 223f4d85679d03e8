#pragma once
// `stereoguard eval --stereo`: stereo accuracy of each matcher against GT disparity.
#include <string>

#include "sg/core/params.hpp"

namespace sg::apps {

struct StereoEvalArgs {
  std::string left, right, gt;  ///< one pair, or
  std::string dir;              ///< a dataset folder (io::find_stereo_gt_pairs)
  double gt_scale = 0;          ///< 8-bit GT: disparity = value / scale; 0 = from datasets.xml
  std::string matchers;         ///< comma-separated: bm, sgbm, fast, fast-sad, fast-census, longseq
  std::string json;             ///< write the rows and means here when not empty
  core::BmParams base;          ///< block size, thresholds (from --config / flags)
  bool auto_range = true;       ///< range per pair from the GT, unless --num-disparities
};

void eval_stereo_main(const StereoEvalArgs& args);

}  // namespace sg::apps
