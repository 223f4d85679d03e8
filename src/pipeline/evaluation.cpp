#include "sg/pipeline/evaluation.hpp"

#include <map>

namespace sg::pipeline {
namespace {

/// Forwards a source and records the truth of each frame as it is read, so that the truth is
/// right even when detections come out later than the frames go in.
class RecordingSource : public core::FrameSource {
 public:
  RecordingSource(core::FrameSource& inner, const TruthLookup& truth_of)
      : inner_(inner), truth_of_(truth_of) {}
  std::optional<core::StereoFrame> next() override {
    std::optional<core::StereoFrame> frame = inner_.next();
    if (frame) truths_.emplace(frame->index, truth_of_(frame->index));
    return frame;
  }
  const core::Camera& camera() const override { return inner_.camera(); }
  int size() const override { return inner_.size(); }
  FrameTruthView take(int index) {
    auto it = truths_.find(index);
    FrameTruthView view = std::move(it->second);
    truths_.erase(it);
    return view;
  }

 private:
  core::FrameSource& inner_;
  const TruthLookup& truth_of_;
  std::map<int, FrameTruthView> truths_;
};

}  // namespace

Evaluation evaluate(core::FrameSource& source, const TruthLookup& truth_of,
                    const RunOptions& options, const DetectionSink& sink) {
  RecordingSource recording(source, truth_of);
  eval::DetectionEvaluator evaluator;
  Evaluation result;
  result.summary = run(recording, options,
                       [&](const core::StereoFrame& frame, const core::Detection& detection) {
                         const FrameTruthView view = recording.take(detection.frame);
                         evaluator.add(detection, view.truth, view.danger);
                         if (sink) sink(frame, detection);
                       });
  result.report = evaluator.report();
  return result;
}

}  // namespace sg::pipeline
