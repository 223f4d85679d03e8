#pragma once
/// Runs the pipeline on a source with ground truth and scores the detections (the `eval` command).
#include <functional>

#include "sg/core/ground_truth.hpp"
#include "sg/eval/detection_metrics.hpp"
#include "sg/pipeline/runner.hpp"

namespace sg::pipeline {

/// Ground truth of one frame as the evaluator needs it.
struct FrameTruthView {
  core::FrameTruth truth;
  cv::Mat danger;  ///< CV_8U 255 = dangerous; may be empty
};

/// Called right after source.next() returned frame `index`: its ground truth.
using TruthLookup = std::function<FrameTruthView(int index)>;

struct Evaluation {
  eval::DetectionReport report;
  RunSummary summary;
};

/// Runs `options` over `source`, pairing each detection with the truth of its frame.
/// `sink` (may be empty) also sees every detection.
Evaluation evaluate(core::FrameSource& source, const TruthLookup& truth_of,
                    const RunOptions& options, const DetectionSink& sink = {});

}  // namespace sg::pipeline
