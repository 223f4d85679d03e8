#pragma once
/// Ray caster for scenarios: left and right 8-bit images plus per-frame ground truth.
#include "sg/core/frame.hpp"
#include "sg/core/ground_truth.hpp"
#include "sg/core/source.hpp"
#include "sg/sim/scenario.hpp"

namespace sg::sim {

struct RenderedFrame {
  core::StereoFrame frame;  ///< left/right CV_8UC1, time_s = index / fps
  core::TruthMaps maps;     ///< disparity, backward flow (empty for frame 0), danger, ids
  core::FrameTruth truth;
};

/// Pure function of (scenario, frame index): rendering frame i never depends on other frames.
class Renderer {
 public:
  explicit Renderer(Scenario scenario);
  RenderedFrame render(int index) const;
  const Scenario& scenario() const { return scenario_; }

 private:
  Scenario scenario_;
};

/// A FrameSource that renders a scenario on the fly; keeps the truth of the last frame.
class ScenarioSource : public core::FrameSource {
 public:
  explicit ScenarioSource(Scenario scenario);
  std::optional<core::StereoFrame> next() override;
  const core::Camera& camera() const override;
  int size() const override;
  /// Ground truth of the frame last returned by next().
  const core::FrameTruth& last_truth() const { return last_.truth; }
  const core::TruthMaps& last_maps() const { return last_.maps; }

 private:
  Renderer renderer_;
  int next_index_ = 0;
  RenderedFrame last_;
};

}  // namespace sg::sim
