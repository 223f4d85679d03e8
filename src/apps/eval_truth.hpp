#pragma once
// `stereoguard eval --truth FILE`: a recording scored against a truth log, for the detector or
// the central-median baseline (docs/real-recordings.md).
#include <optional>
#include <string>

#include "options.hpp"
#include "outputs.hpp"

namespace sg::apps {

struct TruthEvalArgs {
  InputOptions input;
  DetectorOptions detector;
  OutputOptions outputs;
  bool quiet = false;
  std::string json;             ///< write the scores here when not empty
  int drop_every = 0;           ///< drop every n-th frame, 0 = none
  std::string truth;            ///< the truth log; empty = none (baseline only: alarms counted)
  std::string distance_column;  ///< empty = distance_m, else board_distance_m
  std::optional<double> due_within_m;
  std::optional<std::string> quiet_phases;  ///< comma-separated; default eval::default_quiet_phases
  std::string baseline;                     ///< "" = the detector, "central-median" = the baseline
};

void eval_truth_main(const TruthEvalArgs& args);

}  // namespace sg::apps
