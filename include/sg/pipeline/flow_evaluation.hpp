#pragma once
/// Optical-flow accuracy evaluation (`stereoguard eval --flow`): each flow method on each pair of
/// a GT dataset, scored by eval::flow_accuracy. The twin of stereo_evaluation.hpp.
#include <functional>
#include <string>
#include <vector>

#include "sg/core/params.hpp"
#include "sg/eval/flow_metrics.hpp"
#include "sg/io/gt_formats.hpp"

namespace sg::pipeline {

struct FlowEvalRow {
  std::string pair;  ///< io::FlowGtPair::name
  core::FlowMethod method = core::FlowMethod::kDisUltrafast;
  eval::FlowAccuracy accuracy;
};

/// Runs every method (its default FlowParams otherwise) on every pair, in order, and calls
/// `on_row` after each (pair, method). The images are read as gray by cv::imread
/// (IMREAD_GRAYSCALE), as evaluate_stereo reads its pairs. The GT is forward (first -> second)
/// while compute_flow gives the backward flow of its first image, so the first image plays
/// "current" and the second "previous". Throws core::InputError, before any row, when a file of
/// any pair is missing, and at a pair that cannot be decoded or whose sizes differ.
std::vector<FlowEvalRow> evaluate_flow(const std::vector<io::FlowGtPair>& pairs,
                                       const std::vector<core::FlowMethod>& methods,
                                       const std::function<void(const FlowEvalRow&)>& on_row);

}  // namespace sg::pipeline
