#pragma once
// `stereoguard eval --suite random`: the randomised scene suite (docs/random-suite.md).
#include <optional>
#include <string>

#include "options.hpp"

namespace sg::apps {

struct SuiteEvalArgs {
  std::string suite;              ///< only "random"
  std::optional<int> count;       ///< scenes (required)
  std::optional<long long> seed;  ///< first scene's seed (required)
  std::string max_size;           ///< "WxH" cap, empty = none
  int max_frames = 0;             ///< frames per scene at most, 0 = none
  int jobs = 0;                   ///< scenes at once, 0 = all cores
  DetectorOptions detector;
  bool quiet = false;
  std::string json;  ///< per-scene results and the summary, empty = none
  std::string plot;  ///< PNG of the lead and false-alarm histograms, empty = none
};

void eval_suite_main(const SuiteEvalArgs& args);

}  // namespace sg::apps
